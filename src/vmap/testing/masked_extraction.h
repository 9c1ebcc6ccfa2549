#pragma once
// What a matcher that leaves features out must do within a camera mask (Matcher::ExtractFrameWithin,
// features/camera_mask.h): the features outside the mask gone, those inside as the matcher finds them without one.

#include <set>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "vmap/features/matcher.h"

namespace vmap::testing {

// `image0` with its left half masked: each of its features is one the matcher finds without the mask (the same
// descriptor), fewer of them, and its matches with `image1` lie on the kept half, where those of the whole image do
// not all lie.
inline void ExpectFeaturesWithinTheMask(const Matcher& matcher, const cv::Mat& image0, const cv::Mat& image1) {
  cv::Mat mask(image0.size(), CV_8UC1, cv::Scalar(255));
  mask.colRange(0, image0.cols / 2).setTo(0);
  const auto all = matcher.Extract(image0);
  const auto within = matcher.ExtractFrameWithin(image0, cv::Mat(), mask);
  ASSERT_NE(within, nullptr);
  const cv::Mat all_rows = all->descriptors(), within_rows = within->descriptors();
  ASSERT_EQ(within_rows.rows, within->num_features());
  std::set<std::string> found_without_mask;
  for (int i = 0; i < all_rows.rows; ++i) {
    found_without_mask.emplace(all_rows.row(i).ptr<char>(),
                               all_rows.row(i).ptr<char>() + all_rows.row(i).cols * all_rows.elemSize());
  }
  for (int j = 0; j < within_rows.rows; ++j) {
    const std::string row(within_rows.row(j).ptr<char>(),
                          within_rows.row(j).ptr<char>() + within_rows.cols * within_rows.elemSize());
    EXPECT_EQ(found_without_mask.count(row), 1u) << "feature " << j << " is not one found without the mask";
  }
  EXPECT_GT(within->num_features(), all->num_features() / 5);
  EXPECT_LT(within->num_features(), all->num_features() * 4 / 5);

  const auto other = matcher.Extract(image1);
  const float middle = image0.cols / 2.f - 0.5f;
  const TentativeMatches from_within = matcher.Match(*within, *other);
  ASSERT_GT(from_within.size(), 10u);
  for (const cv::Point2f& p : from_within.points0) EXPECT_GE(p.x, middle);
  int left = 0;
  for (const cv::Point2f& p : matcher.Match(*all, *other).points0) left += p.x < middle;
  EXPECT_GT(left, 10);
}

}  // namespace vmap::testing
