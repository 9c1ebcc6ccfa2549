#include "vmap/features/point_features_bytes.h"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace vmap {
namespace {

constexpr size_t kTagSize = 8;

struct Header {
  char tag[kTagSize];
  int32_t width, height, count, dimensions;
};

// Far beyond any detector's keypoints or descriptor width: a header above them is damage, not data.
constexpr int32_t kMaxCount = 1 << 24;
constexpr int32_t kMaxDimensions = 1 << 12;

}  // namespace

std::string EncodePointFeatures(std::string_view tag, const PointFeatureRows& features) {
  if (tag.size() != kTagSize) throw std::invalid_argument("EncodePointFeatures: the tag must be 8 characters");
  const cv::Mat& rows = features.descriptors;
  const int count = static_cast<int>(features.keypoints.size());
  if (count > 0 && (rows.type() != CV_32F || rows.rows != count)) {
    throw std::invalid_argument("EncodePointFeatures: one CV_32F descriptor row per keypoint needed");
  }
  Header header{};
  std::memcpy(header.tag, tag.data(), kTagSize);
  header.width = features.image_size.width;
  header.height = features.image_size.height;
  header.count = count;
  header.dimensions = count > 0 ? rows.cols : 0;
  std::string bytes(reinterpret_cast<const char*>(&header), sizeof(header));
  bytes.reserve(sizeof(header) + count * (2 + header.dimensions) * sizeof(float));
  for (const cv::Point2f& p : features.keypoints) {
    bytes.append(reinterpret_cast<const char*>(&p.x), sizeof(float));
    bytes.append(reinterpret_cast<const char*>(&p.y), sizeof(float));
  }
  for (int r = 0; r < count; ++r) {
    bytes.append(reinterpret_cast<const char*>(rows.ptr<float>(r)), header.dimensions * sizeof(float));
  }
  return bytes;
}

std::optional<PointFeatureRows> DecodePointFeatures(std::string_view tag, std::string_view bytes) {
  Header header;
  if (tag.size() != kTagSize || bytes.size() < sizeof(header)) return std::nullopt;
  std::memcpy(&header, bytes.data(), sizeof(header));
  if (std::memcmp(header.tag, tag.data(), kTagSize) != 0 || header.width < 0 || header.height < 0 || header.count < 0 ||
      header.count > kMaxCount || header.dimensions < 0 || header.dimensions > kMaxDimensions ||
      (header.count > 0 && header.dimensions == 0)) {
    return std::nullopt;
  }
  const size_t count = static_cast<size_t>(header.count);
  const size_t expected = sizeof(header) + count * 2 * sizeof(float) + count * header.dimensions * sizeof(float);
  if (bytes.size() != expected) return std::nullopt;
  PointFeatureRows features;
  features.image_size = cv::Size(header.width, header.height);
  const char* cursor = bytes.data() + sizeof(header);
  features.keypoints.resize(count);
  for (cv::Point2f& p : features.keypoints) {
    std::memcpy(&p.x, cursor, sizeof(float));
    std::memcpy(&p.y, cursor + sizeof(float), sizeof(float));
    cursor += 2 * sizeof(float);
  }
  if (count > 0) {
    features.descriptors.create(header.count, header.dimensions, CV_32F);
    std::memcpy(features.descriptors.data, cursor, count * header.dimensions * sizeof(float));
  }
  return features;
}

}  // namespace vmap
