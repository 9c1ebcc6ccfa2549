#include "vmap/geometry/degensac.h"

#include <cmath>
#include <limits>
#include <vector>

namespace vmap::internal {
namespace {

constexpr double kHomographySquaredThreshold = 5.0;  // px^2, the plane test
constexpr int kPlaneAndParallaxIterations = 100;

}  // namespace

bool RecoverIfDegenerate(const NormalizedPoints& points, const SevenPointSample& sample, const Model& model,
                         MagsacScorer& scorer, RandomStream& random, Model* recovered, Score* recovered_score) {
  const int n = static_cast<int>(points.pixels.size());
  const Mat3 F = ToMatrix(model);
  Vec3 e1 = F.col(0).cross(F.col(2));  // e1^T F = 0: the epipole in the second image
  if (e1.squaredNorm() < 1e-20) e1 = F.col(1).cross(F.col(2));
  const Mat3 A = Skew(e1) * F;
  static const int kTriplets[5][3] = {{0, 1, 2}, {3, 4, 5}, {0, 1, 6}, {3, 4, 6}, {2, 5, 6}};
  auto squared_transfer_error = [&](const Mat3& H, const Point& p) {
    const Vec3 x = H * Vec3(p.x0, p.y0, 1.0);
    if (x.z() == 0) return std::numeric_limits<double>::infinity();
    const double dx = x.x() / x.z() - p.x1, dy = x.y() / x.z() - p.y1;
    return dx * dx + dy * dy;
  };
  bool degenerate = false;
  *recovered_score = Score{};
  for (const auto& triplet : kTriplets) {
    Mat3 M;
    Vec3 b;
    for (int k = 0; k < 3; ++k) {
      const Point& p = points.pixels[sample[triplet[k]]];
      const Vec3 x0(p.x0, p.y0, 1.0), x1(p.x1, p.y1, 1.0);
      const Vec3 x1_e1 = x1.cross(e1);
      b(k) = x1.cross(A * x0).dot(x1_e1) / x1_e1.squaredNorm();
      M.row(k) = x0.transpose();
    }
    if (std::abs(M.determinant()) < 1e-12) continue;
    Mat3 H = A - e1 * (M.inverse() * b).transpose();
    int off_plane = 0;
    for (int s = 0; s < kSevenPointSampleSize && off_plane <= 2; ++s) {
      if (squared_transfer_error(H, points.pixels[sample[s]]) > kHomographySquaredThreshold) ++off_plane;
    }
    if (off_plane > 2) continue;
    degenerate = true;
    // Refit H on all the points it explains, then search the epipole with pairs of points off the plane.
    std::vector<int> on_plane;
    std::vector<char> off(n);
    for (int i = 0; i < n; ++i) {
      if (squared_transfer_error(H, points.pixels[i]) < kHomographySquaredThreshold) on_plane.push_back(i);
    }
    Mat3 refined_H;
    if (FitHomography(points, on_plane, static_cast<int>(on_plane.size()), &refined_H)) H = refined_H;
    for (int i = 0; i < n; ++i) off[i] = squared_transfer_error(H, points.pixels[i]) > kHomographySquaredThreshold;
    int max_iterations = kPlaneAndParallaxIterations;
    for (int it = 0; it < max_iterations; ++it) {
      const int a = random.Uniform(n);
      int c = random.Uniform(n);
      while (c == a && n > 1) c = random.Uniform(n);
      if (!off[a] || !off[c]) continue;
      const Point& pa = points.pixels[a];
      const Point& pc = points.pixels[c];
      const Vec3 la = Vec3(pa.x1, pa.y1, 1.0).cross(H * Vec3(pa.x0, pa.y0, 1.0));
      const Vec3 lc = Vec3(pc.x1, pc.y1, 1.0).cross(H * Vec3(pc.x0, pc.y0, 1.0));
      const Mat3 candidate = Skew(la.cross(lc)) * H;
      if (!candidate.allFinite() || candidate.norm() == 0) continue;
      const Model candidate_model = ToModel(candidate);
      const Score score = scorer.Evaluate(candidate_model, recovered_score->value, nullptr);
      if (score.value > recovered_score->value) {
        *recovered_score = score;
        *recovered = candidate_model;
        const double w = static_cast<double>(score.inliers) / n;
        const double needed = std::log(0.05) / std::log1p(-w * w);
        if (std::isfinite(needed) && needed < max_iterations) max_iterations = static_cast<int>(needed);
      }
    }
  }
  return degenerate;
}

}  // namespace vmap::internal
