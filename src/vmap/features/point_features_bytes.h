#pragma once
// Keypoints with float descriptor rows (XFeat's and ALIKED's features) as bytes and back: what those matchers
// keep in the localization cache (localization/key_image_store.h), as ORB keeps its own.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

struct PointFeatureRows {
  cv::Size image_size;
  std::vector<cv::Point2f> keypoints;
  cv::Mat descriptors;  // CV_32F, one row per keypoint (empty when there are none)
};

// A header (the matcher's 8-byte tag, width, height, count, descriptor width), the keypoints as float32 x, y,
// then the descriptor rows. Little-endian (x86/ARM), read back only by the same build's matcher. `tag` must be
// 8 characters; `descriptors` CV_32F with one row per keypoint.
std::string EncodePointFeatures(std::string_view tag, const PointFeatureRows& features);

// The features written by EncodePointFeatures with the same `tag`; nullopt for bytes of another tag, a size
// that does not fit the header, or a header out of range (a damaged cache is recomputed, never trusted).
std::optional<PointFeatureRows> DecodePointFeatures(std::string_view tag, std::string_view bytes);

}  // namespace vmap
