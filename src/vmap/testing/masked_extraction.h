#pragma once
// What a matcher that leaves features out must do within a camera mask (Matcher::ExtractFrameWithin,
// features/camera_mask.h): the features outside the mask gone, those inside as the matcher finds them without one.

#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "vmap/features/camera_mask.h"
#include "vmap/features/matcher.h"
#include "vmap/features/point_features_bytes.h"

namespace vmap::testing {

// The keypoints of point features (XFeat's, ALIKED's), read back from the bytes the localization cache keeps them
// in (their first 8 are the matcher's tag): ImageFeatures does not expose them.
inline std::vector<cv::Point2f> KeypointsOf(const Matcher& matcher, const ImageFeatures& features) {
  const std::string bytes = matcher.SerializeFeatures(features);
  const auto rows = DecodePointFeatures(std::string_view(bytes).substr(0, 8), bytes);
  EXPECT_TRUE(rows.has_value()) << matcher.name() << "'s features are not point features";
  return rows ? rows->keypoints : std::vector<cv::Point2f>();
}

// Each of `within`'s features lies where `keep` keeps and is one of `every`'s: the same position, and its descriptor
// within `tolerance` (float rounding: a network may describe its keypoints as one batch). Returns, for each, its index
// in `every` (-1 where none is found, a failure already).
inline std::vector<int> ExpectEachFoundWithoutTheMask(const Matcher& matcher, const ImageFeatures& within,
                                                      const ImageFeatures& every, const cv::Mat& keep,
                                                      double tolerance) {
  std::map<std::pair<float, float>, int> found_without_mask;
  const std::vector<cv::Point2f> every_point = KeypointsOf(matcher, every), within_point = KeypointsOf(matcher, within);
  for (size_t i = 0; i < every_point.size(); ++i) found_without_mask[{every_point[i].x, every_point[i].y}] = int(i);
  const cv::Mat every_rows = every.descriptors(), within_rows = within.descriptors();
  EXPECT_EQ(within_rows.rows, within.num_features());
  std::vector<int> index(within_point.size(), -1);
  for (size_t j = 0; j < within_point.size(); ++j) {
    EXPECT_TRUE(KeptByMask(keep, within_point[j])) << "feature " << j << " lies outside the mask";
    const auto found = found_without_mask.find({within_point[j].x, within_point[j].y});
    if (found == found_without_mask.end()) {
      ADD_FAILURE() << "feature " << j << " is not one found without the mask";
      continue;
    }
    index[j] = found->second;
    EXPECT_LE(cv::norm(within_rows.row(int(j)), every_rows.row(found->second), cv::NORM_INF), tolerance)
        << "feature " << j;
  }
  return index;
}

// `image0` with its left half masked: each of its features is one the matcher finds without the mask (the same
// position, the same descriptor but for float rounding: a network describes its keypoints as one batch), fewer of
// them, and its matches with `image1` lie on the kept half, where those of the whole image do not all lie.
inline void ExpectFeaturesWithinTheMask(const Matcher& matcher, const cv::Mat& image0, const cv::Mat& image1) {
  cv::Mat mask(image0.size(), CV_8UC1, cv::Scalar(255));
  mask.colRange(0, image0.cols / 2).setTo(0);
  const auto all = matcher.Extract(image0);
  const auto within = matcher.ExtractFrameWithin(image0, cv::Mat(), mask);
  ASSERT_NE(within, nullptr);
  ExpectEachFoundWithoutTheMask(matcher, *within, *all, mask, 1e-5);
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
