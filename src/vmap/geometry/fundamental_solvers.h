#pragma once
// The fundamental matrix's solvers for vmap's MAGSAC++ (magsac.cc): the 7-point algorithm on a minimal sample,
// the weighted normalised 8-point algorithm on many points, and the homography's DLT (DEGENSAC's plane). They
// work on the correspondences Hartley-normalised. Internal to geometry/.

#include <array>
#include <vector>

#include <Eigen/Dense>

#include "vmap/geometry/sampson_error.h"

namespace vmap::internal {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

constexpr int kSevenPointSampleSize = 7;
constexpr int kSevenPointMaxModels = 3;
using SevenPointSample = std::array<int, kSevenPointSampleSize>;
using SevenPointModels = std::array<Model, kSevenPointMaxModels>;

// F as a model, scaled to unit norm; and back.
Model ToModel(const Mat3& F);
Mat3 ToMatrix(const Model& m);
// [v]x, the cross-product matrix.
Mat3 Skew(const Vec3& v);

// The correspondences in pixels (in the estimator's visiting order) and Hartley-normalised for the solvers.
struct NormalizedPoints {
  std::vector<Point> pixels;
  std::vector<Point> normalized;
  Mat3 T0, T1;  // normalised = T * pixel, per image

  // Fills `normalized` and T0, T1 from `pixels`: false when an image's points all coincide.
  bool Normalize();
};

// The 7-point algorithm, in normalised coordinates: the two-dimensional null space of the 7x9 epipolar system
// (Gaussian elimination, partial pivoting on the first seven columns, full pivoting when one has no pivot),
// then the real roots a of det(a F1 + (1 - a) F2) = 0. Models breaking the oriented epipolar constraint are
// dropped before they are brought back to pixels.
// A sample whose points did not move is solved apart (SolveStationary, fundamental_solvers.cc); `stationary` says
// so. Returns how many models were written to `models`.
int SolveSevenPoint(const NormalizedPoints& points, const SevenPointSample& sample, SevenPointModels* models,
                    bool* stationary);

// Weighted normalised 8-point algorithm (rows scaled by the weights, none: 1) on points[indices[0..count)],
// rank 2 enforced; false with fewer than 8 points or no solution.
bool FitFundamental(const NormalizedPoints& points, const std::vector<int>& indices, int count,
                    const std::vector<double>* weights, Model* model);

// Normalised DLT for x1 ~ H x0 (pixels) on points[indices[0..count)].
bool FitHomography(const NormalizedPoints& points, const std::vector<int>& indices, int count, Mat3* H);

}  // namespace vmap::internal
