#include "vmap/map/visual_map.h"

#include <gtest/gtest.h>

#include "vmap/core/error.h"

namespace vmap {

TEST(MapQuality, ArithmeticMeanReproducesThePapersTable) {
  // Table 4 of the paper, tau = 0.9: n = 3703, m = 3566, Q = 0.48 needs a mean similarity near 0.92.
  const std::vector<double> similarities(3565, 0.923);
  EXPECT_NEAR(MapQuality(3703, 3566, similarities, QualityMean::kArithmetic), 0.48, 0.005);
  // A harmonic mean of 0.037 and 0.923 would be 0.07: the paper's numbers are the arithmetic mean.
  EXPECT_NEAR(MapQuality(3703, 3566, similarities, QualityMean::kHarmonic), 0.0711, 0.001);
}

TEST(MapQuality, EdgeCases) {
  EXPECT_EQ(MapQuality(1, 1, {}, QualityMean::kArithmetic), 0.0);
  EXPECT_EQ(MapQuality(0, 0, {}, QualityMean::kArithmetic), 0.0);
  EXPECT_DOUBLE_EQ(MapQuality(10, 2, {1.0}, QualityMean::kArithmetic), 0.5 * (0.8 + 1.0));
  EXPECT_EQ(MapQuality(2, 2, {0.0}, QualityMean::kHarmonic), 0.0);
  EXPECT_THROW(ParseQualityMean("geometric"), InputError);
}

TEST(MapStatistics, SummarisesLinks) {
  VisualMap map;
  map.num_frames = 10;
  map.key_images.resize(3);
  Link a, b;
  a.num_verified = 40;
  a.similarity = 0.8;
  b.num_verified = 20;
  b.similarity = 0.6;
  b.below_tau = true;
  map.links = {a, b};
  const MapStatistics s = ComputeStatistics(map, QualityMean::kArithmetic);
  EXPECT_EQ(s.num_key_images, 3);
  EXPECT_EQ(s.min_verified, 20);
  EXPECT_EQ(s.max_verified, 40);
  EXPECT_DOUBLE_EQ(s.mean_verified, 30.0);
  EXPECT_DOUBLE_EQ(s.mean_similarity, 0.7);
  EXPECT_EQ(s.below_tau_links, 1);
  EXPECT_DOUBLE_EQ(s.quality, 0.5 * (0.7 + 0.7));
}

}  // namespace vmap
