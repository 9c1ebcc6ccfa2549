#include "vmap/features/point_features_bytes.h"

#include <cstring>

#include <gtest/gtest.h>

namespace vmap {
namespace {

constexpr std::string_view kTag = "vmapTEST";

PointFeatureRows SomeFeatures(int count, int dimensions) {
  PointFeatureRows f;
  f.image_size = cv::Size(640, 480);
  cv::RNG rng(7);
  for (int i = 0; i < count; ++i) f.keypoints.emplace_back(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f));
  if (count > 0) {
    f.descriptors.create(count, dimensions, CV_32F);
    rng.fill(f.descriptors, cv::RNG::UNIFORM, -1.0, 1.0);
  }
  return f;
}

TEST(PointFeaturesBytes, RoundTripIsExact) {
  for (int count : {0, 1, 37}) {
    const PointFeatureRows original = SomeFeatures(count, 64);
    const auto decoded = DecodePointFeatures(kTag, EncodePointFeatures(kTag, original));
    ASSERT_TRUE(decoded) << count;
    EXPECT_EQ(decoded->image_size, original.image_size);
    EXPECT_EQ(decoded->keypoints, original.keypoints);
    ASSERT_EQ(decoded->descriptors.rows, count);
    if (count > 0) {
      EXPECT_EQ(cv::norm(decoded->descriptors, original.descriptors, cv::NORM_INF), 0.0);
    }
  }
}

TEST(PointFeaturesBytes, DamagedOrForeignBytesAreRefused) {
  const std::string bytes = EncodePointFeatures(kTag, SomeFeatures(5, 128));
  EXPECT_FALSE(DecodePointFeatures("vmapELSE", bytes));                        // another matcher's
  EXPECT_FALSE(DecodePointFeatures(kTag, bytes.substr(0, bytes.size() - 1)));  // truncated
  EXPECT_FALSE(DecodePointFeatures(kTag, bytes + "x"));                        // trailing bytes
  EXPECT_FALSE(DecodePointFeatures(kTag, bytes.substr(0, 10)));                // no whole header
  std::string huge = bytes;
  const int32_t count = 1 << 30;
  std::memcpy(huge.data() + 16, &count, sizeof(count));  // the count field after tag, width, height
  EXPECT_FALSE(DecodePointFeatures(kTag, huge));
}

TEST(PointFeaturesBytes, MismatchedRowsAreAProgrammingError) {
  PointFeatureRows f = SomeFeatures(3, 8);
  f.descriptors = f.descriptors.rowRange(0, 2).clone();
  EXPECT_THROW(EncodePointFeatures(kTag, f), std::invalid_argument);
  EXPECT_THROW(EncodePointFeatures("short", SomeFeatures(1, 8)), std::invalid_argument);
}

}  // namespace
}  // namespace vmap
