#include "vmap/features/orb_extraction.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/features/matcher_options_json.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

cv::Mat SyntheticGray(int frame = 0) {
  testing::SyntheticOptions options;
  options.num_frames = frame + 1;
  const auto sequence = testing::RenderSyntheticSequence(options);
  cv::Mat gray;
  cv::cvtColor(sequence.frames[frame], gray, cv::COLOR_BGR2GRAY);
  return gray;
}

// Strong corners on the left half, corners of contrast 12 (under FAST's 20, over its fallback 7) on the right.
cv::Mat StrongLeftFaintRight() {
  cv::Mat image(120, 160, CV_8U, cv::Scalar(100));
  cv::RNG rng(5);
  for (int i = 0; i < 60; ++i) {
    const int x = rng.uniform(4, 148), y = rng.uniform(4, 108);
    const int contrast = x < 76 ? 120 : 12;
    cv::rectangle(image, cv::Rect(x, y, 8, 8), cv::Scalar(100 + contrast), cv::FILLED);
  }
  return image;
}

OrbMatcherOptions GridOptions() {
  OrbMatcherOptions options;
  options.grid_cell = 30;
  options.edge_threshold = 16;
  return options;
}

int CountRightOf(const std::vector<cv::KeyPoint>& keypoints, float x) {
  return static_cast<int>(std::count_if(keypoints.begin(), keypoints.end(), [&](const auto& k) { return k.pt.x > x; }));
}

}  // namespace

TEST(OrbGridExtraction, CellsWithoutStrongCornersTakeTheFallbackThreshold) {
  const cv::Mat image = StrongLeftFaintRight();
  OrbGridExtraction options;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  ExtractOrbOnGrid(image, options, keypoints, descriptors);
  ASSERT_EQ(descriptors.rows, static_cast<int>(keypoints.size()));
  EXPECT_GE(CountRightOf(keypoints, 84), 10);           // the faint half has features
  options.min_fast_threshold = options.fast_threshold;  // no fallback: the faint half has none
  ExtractOrbOnGrid(image, options, keypoints, descriptors);
  EXPECT_EQ(CountRightOf(keypoints, 84), 0);
  EXPECT_GT(keypoints.size(), 0u);
}

TEST(OrbGridExtraction, BorderIsPerLevelAndFeaturesSpreadOverLevels) {
  const cv::Mat gray = SyntheticGray();
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  OrbGridExtraction options;
  ExtractOrbOnGrid(gray, options, keypoints, descriptors);
  ASSERT_GT(keypoints.size(), 200u);
  EXPECT_LE(keypoints.size(), 500u);
  EXPECT_EQ(descriptors.rows, static_cast<int>(keypoints.size()));
  std::vector<int> per_level(options.num_levels, 0);
  float nearest_edge = 1e9f;
  for (const cv::KeyPoint& k : keypoints) {
    ASSERT_GE(k.octave, 0);
    ASSERT_LT(k.octave, options.num_levels);
    ++per_level[k.octave];
    const float scale = static_cast<float>(std::pow(options.scale_factor, k.octave));
    // Never nearer the edge than the border at the keypoint's level.
    EXPECT_GE(std::min(k.pt.x, k.pt.y) / scale, options.border - 0.5f);
    EXPECT_GE(std::min(gray.cols - 1 - k.pt.x, gray.rows - 1 - k.pt.y) / scale, options.border - 1.0f);
    nearest_edge = std::min({nearest_edge, k.pt.x, k.pt.y});
  }
  EXPECT_LT(nearest_edge, 31.0f);  // OpenCV's fixed 31 px would not reach here
  EXPECT_GT(per_level[0], per_level[2]);
  EXPECT_GT(per_level[2], 0);
  EXPECT_GT(per_level[4], 0);
}

TEST(OrbGridExtraction, OrientationMakesFeaturesMatchARotatedImage) {
  const cv::Mat gray = SyntheticGray();
  cv::Mat rotated;
  cv::rotate(gray, rotated, cv::ROTATE_90_CLOCKWISE);  // (x, y) -> (rows - 1 - y, x)
  const auto matcher = CreateOrbMatcher(GridOptions());
  const TentativeMatches matches = matcher->Match(*matcher->Extract(gray), *matcher->Extract(rotated));
  int right = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    const cv::Point2f expected(gray.rows - 1 - matches.points0[i].y, matches.points0[i].x);
    right += cv::norm(matches.points1[i] - expected) < 3.0;
  }
  EXPECT_GT(right, 100);  // with every angle 0 (no orientation), few of them survive a quarter turn
}

TEST(OrbMatcher, ClaheFindsTheFeaturesOfADarkImage) {
  const cv::Mat gray = SyntheticGray();
  cv::Mat dark;
  gray.convertTo(dark, CV_8U, 0.12);  // a scene under a twelfth of the light
  OrbMatcherOptions options;
  const auto plain = CreateOrbMatcher(options);
  options.clahe_clip = 2.0;
  const auto equalised = CreateOrbMatcher(options);
  const int without = plain->Extract(dark)->num_features();
  const int with = equalised->Extract(dark)->num_features();
  EXPECT_LT(without, 100);
  EXPECT_GT(with, 3 * std::max(without, 30));
}

TEST(OrbMatcher, AMapWithoutTheNewFieldsExtractsAsBefore) {
  // A map.json written before grid_cell, min_fast_threshold and clahe_clip existed.
  const MatcherOptions read = MatcherOptionsFromJson(
      R"({"type": "orb", "num_features": 500, "scale_factor": 1.2, "num_levels": 8, "edge_threshold": 31,
          "fast_threshold": 20, "cross_check": true, "ratio": 0.0})",
      "map.json");
  const OrbMatcherOptions& orb = read.model("orb").As<OrbMatcherOptions>();
  EXPECT_EQ(orb.grid_cell, 0);
  EXPECT_EQ(orb.clahe_clip, 0.0);
  const cv::Mat gray = SyntheticGray();
  cv::Ptr<cv::ORB> opencv = cv::ORB::create();
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  opencv->detectAndCompute(gray, cv::noArray(), keypoints, descriptors);
  const auto features = CreateOrbMatcher(orb)->Extract(gray);
  ASSERT_EQ(features->num_features(), static_cast<int>(keypoints.size()));
  EXPECT_EQ(cv::norm(features->descriptors(), descriptors, cv::NORM_HAMMING), 0.0);
}

}  // namespace vmap
