#include "vmap/features/orb_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <tuple>

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {

TEST(BinaryMatching, EqualsOpenCvBruteForceWithCrossCheck) {
  cv::RNG rng(3);
  cv::Mat a(300, 32, CV_8U), b(280, 32, CV_8U);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  rng.fill(b, cv::RNG::UNIFORM, 0, 256);
  // Make half of b noisy copies of rows of a so that there are real matches.
  for (int i = 0; i < 140; ++i) {
    a.row(i * 2).copyTo(b.row(i));
    b.at<uchar>(i, i % 32) ^= 0x5;
  }
  cv::BFMatcher reference(cv::NORM_HAMMING, /*crossCheck=*/true);
  std::vector<cv::DMatch> expected;
  reference.match(a, b, expected);
  const auto ours = MatchBinaryDescriptors(a, b, /*cross_check=*/true, 0.0);
  ASSERT_EQ(ours.size(), expected.size());
  for (size_t k = 0; k < ours.size(); ++k) {
    EXPECT_EQ(ours[k].first, expected[k].queryIdx);
    EXPECT_EQ(ours[k].second, expected[k].trainIdx);
  }
}

// The definition, written as plainly as possible: what the vectorised matcher must reproduce, ties included.
std::vector<std::pair<int, int>> ReferenceMatches(const cv::Mat& query, const cv::Mat& train, bool cross_check,
                                                  double ratio) {
  cv::Mat distance(query.rows, train.rows, CV_32S);
  for (int i = 0; i < query.rows; ++i) {
    for (int j = 0; j < train.rows; ++j)
      distance.at<int>(i, j) = static_cast<int>(cv::norm(query.row(i), train.row(j), cv::NORM_HAMMING));
  }
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < query.rows; ++i) {
    int best = 0;
    for (int j = 1; j < train.rows; ++j) best = distance.at<int>(i, j) < distance.at<int>(i, best) ? j : best;
    int second = INT_MAX;
    for (int j = 0; j < train.rows; ++j)
      if (j != best) second = std::min(second, distance.at<int>(i, j));
    int best_query = 0;
    for (int k = 1; k < query.rows; ++k)
      best_query = distance.at<int>(k, best) < distance.at<int>(best_query, best) ? k : best_query;
    if (cross_check && best_query != i) continue;
    if (ratio > 0 && train.rows > 1 && !(distance.at<int>(i, best) < ratio * second)) continue;
    pairs.emplace_back(i, best);
  }
  return pairs;
}

TEST(BinaryMatching, EqualsThePlainDefinitionForAnySizeWidthAndTies) {
  cv::RNG rng(11);
  for (const auto& [rows_a, rows_b, width] :
       {std::tuple{1, 1, 32}, {7, 5, 32}, {33, 17, 32}, {100, 130, 32}, {40, 31, 64}, {20, 45, 8}}) {
    cv::Mat a(rows_a, width, CV_8U), b(rows_b, width, CV_8U);
    // Few distinct bytes: many equal distances, so the tie rules are exercised.
    rng.fill(a, cv::RNG::UNIFORM, 0, 4);
    rng.fill(b, cv::RNG::UNIFORM, 0, 4);
    for (bool cross_check : {false, true}) {
      for (double ratio : {0.0, 0.8}) {
        EXPECT_EQ(MatchBinaryDescriptors(a, b, cross_check, ratio), ReferenceMatches(a, b, cross_check, ratio))
            << rows_a << "x" << rows_b << " width " << width << " cross_check " << cross_check << " ratio " << ratio;
      }
    }
  }
}

TEST(BinaryMatching, RatioTestRejectsAmbiguousMatches) {
  cv::Mat a = cv::Mat::zeros(1, 32, CV_8U);
  cv::Mat b = cv::Mat::zeros(2, 32, CV_8U);
  b.at<uchar>(0, 0) = 0x1;  // distance 1
  b.at<uchar>(1, 0) = 0x3;  // distance 2: ambiguous at ratio 0.5
  EXPECT_EQ(MatchBinaryDescriptors(a, b, false, 0.0).size(), 1u);
  EXPECT_TRUE(MatchBinaryDescriptors(a, b, false, 0.5).empty());
  EXPECT_EQ(MatchBinaryDescriptors(a, b, false, 0.8).size(), 1u);  // 1 < 0.8 * 2
}

TEST(OrbMatcher, MatchesNeighbouringFramesOfASyntheticScene) {
  testing::SyntheticOptions options;
  options.num_frames = 3;
  const auto sequence = testing::RenderSyntheticSequence(options);
  const auto matcher = CreateOrbMatcher({});
  cv::Mat gray0, gray1;
  cv::cvtColor(sequence.frames[0], gray0, cv::COLOR_BGR2GRAY);
  cv::cvtColor(sequence.frames[2], gray1, cv::COLOR_BGR2GRAY);
  const auto f0 = matcher->Extract(gray0);
  const auto f1 = matcher->Extract(gray1);
  EXPECT_GT(f0->num_features(), 300);
  EXPECT_LE(f0->num_features(), 500);  // OpenCV's default budget
  const TentativeMatches matches = matcher->Match(*f0, *f1);
  EXPECT_GT(matches.size(), 150u);
  EXPECT_EQ(matches.points0.size(), matches.points1.size());
}

TEST(OrbMatcher, MatchingInAWindowFindsTheFeaturesWhereThePredictionPutsThem) {
  // A frame that is its key image moved 12 px to the right: within a window around the true displacement every match
  // moves by it, and around a wrong one (12 px to the left) far fewer features find a candidate good enough.
  testing::SyntheticOptions options;
  options.num_frames = 1;
  cv::Mat key_gray, frame_gray;
  cv::cvtColor(testing::RenderSyntheticSequence(options).frames[0], key_gray, cv::COLOR_BGR2GRAY);
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 12, 0, 1, 0);
  cv::warpAffine(key_gray, frame_gray, shift, key_gray.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  const auto matcher = CreateOrbMatcher({});
  const auto key = matcher->Extract(key_gray);
  const auto frame = matcher->Extract(frame_gray);
  MatchWindow window;
  window.predicted_dx = 12.0;
  window.half_width = 4.0;
  window.half_height = 4.0;
  const TentativeMatches right = MatchOrbInWindow(*frame, *key, window);
  EXPECT_GT(right.size(), 150u);
  int moved = 0;
  for (size_t i = 0; i < right.size(); ++i) {
    EXPECT_LE(std::abs(right.points0[i].x - right.points1[i].x - 12.0), 4.0 + 1e-4);
    EXPECT_LE(std::abs(right.points0[i].y - right.points1[i].y), 4.0 + 1e-4);
    moved += std::abs(right.points0[i].x - right.points1[i].x - 12.0) < 1.5;
  }
  EXPECT_GT(moved, 0.9 * right.size());
  window.predicted_dx = -12.0;
  const TentativeMatches wrong = MatchOrbInWindow(*frame, *key, window);
  EXPECT_LT(wrong.size(), right.size() / 4) << "right " << right.size() << ", wrong " << wrong.size();
  // Each key image feature keeps one match at most.
  std::vector<std::pair<float, float>> keys;
  for (const cv::Point2f& p : right.points1) keys.emplace_back(p.x, p.y);
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(std::unique(keys.begin(), keys.end()), keys.end());
  // The window grows with the distance from the centre by the zoom: more candidates, never fewer matches here.
  window.predicted_dx = 12.0;
  window.zoom = 0.2;
  window.centre = cv::Point2f(key_gray.cols / 2.0f, key_gray.rows / 2.0f);
  EXPECT_GE(MatchOrbInWindow(*frame, *key, window).size() + 10, right.size());
}

TEST(OrbMatcher, BlackImageHasNoFeaturesAndNoMatches) {
  const auto matcher = CreateOrbMatcher({});
  const auto black = matcher->Extract(cv::Mat::zeros(240, 320, CV_8U));
  EXPECT_EQ(black->num_features(), 0);
  EXPECT_EQ(matcher->Match(*black, *black).size(), 0u);
}

// Levels beyond the pyramid's last pixel (scale factor 2 on a 160x120 frame: the 8th level rounds to none) are left
// out: the frame keeps the features of the levels that exist (it had none at all), as with 7 levels asked for.
TEST(OrbMatcher, LevelsBeyondTheLastPixelAreLeftOut) {
  testing::SyntheticOptions scene;
  scene.num_frames = 1;
  cv::Mat gray;
  cv::cvtColor(testing::RenderSyntheticSequence(scene).frames[0], gray, cv::COLOR_BGR2GRAY);
  cv::resize(gray, gray, cv::Size(160, 120), 0, 0, cv::INTER_AREA);
  OrbMatcherOptions eight;
  eight.scale_factor = 2.0;
  eight.num_levels = 8;
  OrbMatcherOptions seven = eight;
  seven.num_levels = 7;
  const auto with_eight = CreateOrbMatcher(eight)->Extract(gray);
  const auto with_seven = CreateOrbMatcher(seven)->Extract(gray);
  EXPECT_GT(with_seven->num_features(), 20);
  ASSERT_EQ(with_eight->num_features(), with_seven->num_features());
  EXPECT_EQ(cv::norm(with_eight->descriptors(), with_seven->descriptors(), cv::NORM_HAMMING), 0.0);
}

TEST(OrbMatcher, OptionsAreChecked) {
  // Named by the JSON keys of the fields; within MatcherOptions, after the model's name.
  OrbMatcherOptions options;
  options.num_features = 0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "num_features");
  options = {};
  options.scale_factor = 1.0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "scale_factor");
  options = {};
  options.ratio = 1.5;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "ratio");
  MatcherOptions all;
  all.Of<OrbMatcherOptions>().num_levels = 0;
  EXPECT_EQ(testing::OptionErrorPath([&] { all.Check(); }), "orb.num_levels");
  EXPECT_EQ(testing::OptionErrorPath([&] { CreateMatcher(all); }), "orb.num_levels");
}

TEST(OrbFeatures, SerialiseAndReadBackExactly) {
  testing::SyntheticOptions options;
  options.num_frames = 2;
  const auto sequence = testing::RenderSyntheticSequence(options);
  const auto matcher = CreateOrbMatcher({});
  cv::Mat gray;
  cv::cvtColor(sequence.frames[0], gray, cv::COLOR_BGR2GRAY);
  const auto features = matcher->Extract(gray);
  const std::string bytes = matcher->SerializeFeatures(*features);
  const auto back = matcher->DeserializeFeatures(bytes);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->num_features(), features->num_features());
  EXPECT_EQ(back->image_size(), features->image_size());
  EXPECT_EQ(cv::norm(back->descriptors(), features->descriptors(), cv::NORM_HAMMING), 0.0);
  const auto a = matcher->Match(*features, *features), b = matcher->Match(*back, *features);
  EXPECT_EQ(a.points0, b.points0);
  EXPECT_EQ(a.points1, b.points1);
  // Bytes that are not ORB features are refused, not misread.
  EXPECT_FALSE(matcher->DeserializeFeatures(bytes.substr(0, bytes.size() - 1)));
  EXPECT_FALSE(matcher->DeserializeFeatures("not features"));
  // An image without features round-trips too.
  const auto empty = matcher->Extract(cv::Mat::zeros(240, 320, CV_8U));
  const auto empty_back = matcher->DeserializeFeatures(matcher->SerializeFeatures(*empty));
  ASSERT_TRUE(empty_back);
  EXPECT_EQ(empty_back->num_features(), 0);
}

}  // namespace vmap
