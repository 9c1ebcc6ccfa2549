#pragma once
// The Sampson error of a correspondence x0 <-> x1 under a fundamental matrix F (x1^T F x0 = 0; an essential
// matrix on normalised points alike): the epipolar residual e = x1^T F x0 over the norm of its gradient,
// sqrt(d) with d = (F x0)_0^2 + (F x0)_1^2 + (F^T x1)_0^2 + (F^T x1)_1^2, the first-order distance of the
// correspondence from its epipolar lines. Written once (EpipolarTermsOf) for every use: the signed error the
// pose refinement minimises, the distances of `vmap eval` and the tests, and the squared error of the
// estimator's innermost loop (geometry/magsac.cc), one at a time and a block at a time.

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

// The two terms of one correspondence's Sampson error; f is F row-major.
struct EpipolarTerms {
  double residual;        // e = x1^T F x0
  double gradient_norm2;  // d, the squared norm of e's gradient in (x0, y0, x1, y1)
};

inline EpipolarTerms EpipolarTermsOf(const double* f, double x0, double y0, double x1, double y1) {
  const double l0 = f[0] * x0 + f[1] * y0 + f[2];  // F x0: the epipolar line of x0 in the second image
  const double l1 = f[3] * x0 + f[4] * y0 + f[5];
  const double l2 = f[6] * x0 + f[7] * y0 + f[8];
  const double m0 = f[0] * x1 + f[3] * y1 + f[6];  // F^T x1, first two entries
  const double m1 = f[1] * x1 + f[4] * y1 + f[7];
  return {x1 * l0 + y1 * l1 + l2, l0 * l0 + l1 * l1 + m0 * m0 + m1 * m1};
}

// The signed Sampson error e / sqrt(d), in the points' units; 0 where the gradient vanishes (x0 and x1 at
// the epipoles).
inline double SignedSampsonError(const cv::Matx33d& F, const cv::Point2d& x0, const cv::Point2d& x1) {
  const EpipolarTerms terms = EpipolarTermsOf(F.val, x0.x, x0.y, x1.x, x1.y);
  return terms.gradient_norm2 > 0 ? terms.residual / std::sqrt(terms.gradient_norm2) : 0.0;
}

// |SignedSampsonError|: the distance, in pixels for pixel coordinates.
inline double SampsonDistance(const cv::Matx33d& F, const cv::Point2d& x0, const cv::Point2d& x1) {
  return std::abs(SignedSampsonError(F, x0, x1));
}

namespace internal {

// One correspondence, pixels: x0 <-> x1.
struct Point {
  double x0, y0, x1, y1;
};

// F row-major in pixels; x1^T F x0 = 0.
using Model = std::array<double, 9>;

// e^2 / d: the estimator compares it with squared thresholds and needs no square root. Infinity where the
// gradient vanishes (no threshold accepts such a point).
inline double SquaredSampson(const Model& f, const Point& p) {
  const EpipolarTerms terms = EpipolarTermsOf(f.data(), p.x0, p.y0, p.x1, p.y1);
  return terms.gradient_norm2 > 0 ? terms.residual * terms.residual / terms.gradient_norm2
                                  : std::numeric_limits<double>::infinity();
}

// Correspondences column by column, the layout SquaredSampsonErrors reads.
struct PointColumns {
  std::vector<double> x0, y0, x1, y1;

  void Assign(const std::vector<Point>& points);
};

// r2[i - begin] = SquaredSampson(f, point i) for i in [begin, end), bit for bit: the same operations in the
// same order, none fused. Written over columns, with the division made unconditional, and compiled without
// trapping math (CMakeLists.txt), so that the compiler vectorises it (four points an instruction with AVX2,
// chosen at run time): the estimator's innermost loop (docs/measurements/code-choices.md, "Sampson errors a
// block at a time").
void SquaredSampsonErrors(const Model& f, const PointColumns& points, int begin, int end, double* r2);

}  // namespace internal
}  // namespace vmap
