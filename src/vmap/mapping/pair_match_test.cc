#include "vmap/mapping/pair_match.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/features/orb_matcher.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

cv::Mat Gray(const cv::Mat& bgr) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

TEST(MatchPair, VerifiesTheMatchesInTheMatchersOrder) {
  testing::SyntheticOptions scene;
  scene.num_frames = 4;
  const testing::SyntheticSequence sequence = testing::RenderSyntheticSequence(scene);
  const auto matcher = CreateOrbMatcher({});
  VerifierOptions verifier;
  verifier.threshold = 1.0;
  const PairMatch pair = MatchPair(*matcher, Gray(sequence.frames[0]), Gray(sequence.frames[3]), verifier);

  // The same matches as the matcher's own, in its order, one inlier flag each.
  const TentativeMatches direct =
      matcher->Match(*matcher->Extract(Gray(sequence.frames[0])), *matcher->Extract(Gray(sequence.frames[3])));
  ASSERT_EQ(pair.matches.size(), direct.size());
  for (size_t i = 0; i < direct.size(); ++i) EXPECT_EQ(pair.matches.points0[i], direct.points0[i]);
  ASSERT_TRUE(pair.fundamental.success);
  ASSERT_EQ(pair.fundamental.inlier_mask.size(), pair.matches.size());
  EXPECT_DOUBLE_EQ(pair.similarity, double(pair.fundamental.num_inliers) / double(pair.matches.size()));
  EXPECT_GT(pair.similarity, 0.5);
  // Its F is the scene's motion: the true F's Sampson errors on the inliers are small.
  const cv::Matx33d F_true = testing::TrueFundamental(sequence.K, sequence.poses[0], sequence.poses[3]);
  int near = 0;
  for (size_t i = 0; i < pair.matches.size(); ++i) {
    if (pair.fundamental.inlier_mask[i])
      near += SampsonDistance(F_true, pair.matches.points0[i], pair.matches.points1[i]) < 2.0;
  }
  EXPECT_GT(near, 0.9 * pair.fundamental.num_inliers);
  EXPECT_GE(pair.extract_seconds, 0.0);
}

TEST(MatchPair, FewerMatchesThanTheVerifierNeedsGiveNoF) {
  const cv::Mat flat(240, 320, CV_8U, cv::Scalar(128));
  const auto matcher = CreateOrbMatcher({});
  const PairMatch pair = MatchPair(*matcher, flat, flat, VerifierOptions{});
  EXPECT_EQ(pair.matches.size(), 0u);
  EXPECT_FALSE(pair.fundamental.success);
  EXPECT_EQ(pair.similarity, 0.0);
}

}  // namespace
}  // namespace vmap
