#include "vmap/geometry/sampson_error.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

namespace vmap::internal {
namespace {

// Bit patterns, so that 0.0 and -0.0, or two infinities, are told apart exactly as the estimator would see them.
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The block version equals the scalar one bit for bit (the estimator's results, and so every map, depend on
// it), for every block start and length, including points on the epipole (zero gradient: infinite error).
TEST(SampsonErrors, BlockEqualsScalarBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pixel(0.0, 1280.0), entry(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Model f;
    for (double& v : f) v = entry(rng) * std::pow(10.0, -3.0 * (&v - f.data()) / 8.0);
    std::vector<Point> points(37);
    for (Point& p : points) p = {pixel(rng), pixel(rng), pixel(rng), pixel(rng)};
    // F = [e]x: a point at the epipole e = (5, 7) in both images has no gradient.
    if (trial == 0) {
      f = {0, -1, 7, 1, 0, -5, -7, 5, 0};
      points[3] = {5, 7, 5, 7};
    }
    PointColumns columns;
    columns.Assign(points);
    for (int begin : {0, 1, 5, 16}) {
      for (int end : {begin, begin + 3, begin + 8, 37}) {
        if (end > 37 || end < begin) continue;
        std::vector<double> r2(end - begin + 1, -1.0);
        SquaredSampsonErrors(f, columns, begin, end, r2.data());
        for (int i = begin; i < end; ++i) {
          const double expected = SquaredSampson(f, points[i]);
          EXPECT_TRUE(SameBits(r2[i - begin], expected))
              << "point " << i << " of block [" << begin << ", " << end << "): " << r2[i - begin] << " vs " << expected;
        }
        EXPECT_EQ(r2[end - begin], -1.0) << "wrote past the block";
      }
    }
  }
  const Model epipolar = {0, -1, 7, 1, 0, -5, -7, 5, 0};
  EXPECT_TRUE(std::isinf(SquaredSampson(epipolar, {5, 7, 5, 7})));
}

// Rectified stereo (the second camera beside the first): epipolar lines are rows, and the Sampson error of a match
// whose rows differ by dy is the least total move that puts both points on one row, dy / sqrt(2), whichever form.
TEST(SampsonError, IsTheDistanceToTheEpipolarLinesInEveryForm) {
  const cv::Matx33d F(0, 0, 0, 0, 0, -1, 0, 1, 0);
  const cv::Point2d x0(10, 20), x1(50, 23);
  EXPECT_DOUBLE_EQ(SignedSampsonError(F, x0, x1), -3.0 / std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(SignedSampsonError(F, x1, x0), 3.0 / std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(SampsonDistance(F, x0, x1), 3.0 / std::sqrt(2.0));
  Model f;
  std::copy(F.val, F.val + 9, f.begin());
  EXPECT_DOUBLE_EQ(SquaredSampson(f, {x0.x, x0.y, x1.x, x1.y}), 4.5);
  EXPECT_EQ(SampsonDistance(F, x0, cv::Point2d(-400, 20)), 0.0) << "anywhere on the row";
  // At the epipoles the gradient vanishes: no distance (signed forms), never an inlier (squared form).
  const cv::Matx33d cross(0, -1, 7, 1, 0, -5, -7, 5, 0);
  EXPECT_EQ(SignedSampsonError(cross, {5, 7}, {5, 7}), 0.0);
}

}  // namespace
}  // namespace vmap::internal
