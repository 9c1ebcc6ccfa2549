#include "vmap/geometry/fundamental_solvers.h"

#include <algorithm>
#include <cmath>

namespace vmap::internal {
namespace {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec9 = Eigen::Matrix<double, 9, 1>;

// Real roots of c3 t^3 + c2 t^2 + c1 t + c0, polished by Newton steps.
int SolveCubic(double c3, double c2, double c1, double c0, double* roots) {
  const double scale = std::max({std::abs(c3), std::abs(c2), std::abs(c1), std::abs(c0)});
  if (scale == 0.0) return 0;
  int count = 0;
  if (std::abs(c3) < 1e-12 * scale) {
    if (std::abs(c2) < 1e-12 * scale) {
      if (std::abs(c1) < 1e-12 * scale) return 0;
      roots[count++] = -c0 / c1;
    } else {
      const double disc = c1 * c1 - 4 * c2 * c0;
      if (disc < 0) return 0;
      const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
      roots[count++] = q / c2;
      if (q != 0) roots[count++] = c0 / q;
    }
  } else {
    const double a = c2 / c3, b = c1 / c3, c = c0 / c3;
    const double p = b - a * a / 3.0, q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
    const double disc = q * q / 4.0 + p * p * p / 27.0;
    if (disc > 0) {
      const double s = std::sqrt(disc);
      roots[count++] = std::cbrt(-q / 2.0 + s) + std::cbrt(-q / 2.0 - s) - a / 3.0;
    } else {
      const double r = std::sqrt(std::max(0.0, -p / 3.0));
      const double cos_arg = r > 0 ? std::clamp(-q / (2.0 * r * r * r), -1.0, 1.0) : 0.0;
      const double phi = std::acos(cos_arg) / 3.0;
      for (int k = 0; k < 3; ++k) roots[count++] = 2.0 * r * std::cos(phi - 2.0 * M_PI * k / 3.0) - a / 3.0;
    }
  }
  for (int i = 0; i < count; ++i) {
    for (int step = 0; step < 2; ++step) {
      const double t = roots[i];
      const double value = ((c3 * t + c2) * t + c1) * t + c0;
      const double slope = (3 * c3 * t + 2 * c2) * t + c1;
      if (slope == 0) break;
      roots[i] = t - value / slope;
    }
  }
  return count;
}

// F in pixels from F in normalised coordinates: T1^T Fn T0 with T = [s 0 tx; 0 s ty; 0 0 1], scaled to unit norm.
bool Denormalize(const NormalizedPoints& points, const double* fn, Model* model) {
  const double s0 = points.T0(0, 0), a0 = points.T0(0, 2), b0 = points.T0(1, 2);
  const double s1 = points.T1(0, 0), a1 = points.T1(0, 2), b1 = points.T1(1, 2);
  double g[9];  // Fn T0
  for (int r = 0; r < 3; ++r) {
    g[3 * r] = s0 * fn[3 * r];
    g[3 * r + 1] = s0 * fn[3 * r + 1];
    g[3 * r + 2] = a0 * fn[3 * r] + b0 * fn[3 * r + 1] + fn[3 * r + 2];
  }
  Model& m = *model;
  for (int c = 0; c < 3; ++c) {
    m[c] = s1 * g[c];
    m[3 + c] = s1 * g[3 + c];
    m[6 + c] = a1 * g[c] + b1 * g[3 + c] + g[6 + c];
  }
  double norm = 0;
  for (double v : m) norm += v * v;
  norm = std::sqrt(norm);
  if (!(norm > 0) || !std::isfinite(norm)) return false;
  const double inverse = 1.0 / norm;
  for (double& v : m) v *= inverse;
  return true;
}

// Chum, Werner & Matas (2004): the sample points must all lie in front of both cameras, i.e. e x x0 and
// F^T x1 point the same way (e: F e = 0) for every point, up to one common sign. Checked in normalised
// coordinates: the normalising similarities keep w > 0 and have positive determinants, so the signs agree with
// those in pixels.
bool OrientedConstraintHolds(const NormalizedPoints& points, const double* m, const SevenPointSample& sample) {
  double e[3] = {m[1] * m[8] - m[2] * m[7], m[2] * m[6] - m[0] * m[8], m[0] * m[7] - m[1] * m[6]};  // row0 x row2
  if (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] < 1e-20) {  // rows 0 and 2 parallel: use rows 1 and 2
    e[0] = m[4] * m[8] - m[5] * m[7], e[1] = m[5] * m[6] - m[3] * m[8], e[2] = m[3] * m[7] - m[4] * m[6];
  }
  double first_sign = 0;
  for (int i = 0; i < kSevenPointSampleSize; ++i) {
    const Point& p = points.normalized[sample[i]];
    const double l0 = m[0] * p.x1 + m[3] * p.y1 + m[6], l1 = m[1] * p.x1 + m[4] * p.y1 + m[7],
                 l2 = m[2] * p.x1 + m[5] * p.y1 + m[8];
    // (e x x0) . l with x0 = (x, y, 1)
    const double c0 = e[1] - e[2] * p.y0, c1 = e[2] * p.x0 - e[0], c2 = e[0] * p.y0 - e[1] * p.x0;
    const double sign = c0 * l0 + c1 * l1 + c2 * l2;
    if (i == 0)
      first_sign = sign;
    else if (sign * first_sign < 0)
      return false;
  }
  return true;
}

// A sample whose points did not move (a frame repeated, a robot standing still) leaves the epipolar system
// rank-deficient: every F = [e]x fits it. OpenCV's USAC returns such an F with every unmoved point an inlier,
// and Algorithm 1 depends on it (a repeated frame must pass, not become a key image); so does this: the
// epipole is put at the sample's centroid. Any other degenerate sample
// yields no model.
int SolveStationary(const NormalizedPoints& points, const SevenPointSample& sample, SevenPointModels* models,
                    bool* stationary) {
  constexpr double kUnmoved = 1e-6;  // pixels
  double cx = 0, cy = 0;
  for (int i : sample) {
    const Point& p = points.pixels[i];
    if (std::abs(p.x1 - p.x0) > kUnmoved || std::abs(p.y1 - p.y0) > kUnmoved) return 0;
    cx += p.x0 / kSevenPointSampleSize;
    cy += p.y0 / kSevenPointSampleSize;
  }
  *stationary = true;
  // [e]x for e = (cx, cy, 1), in pixels, scaled to unit norm as Denormalize does.
  Model& m = (*models)[0];
  m = {0, -1, cy, 1, 0, -cx, -cy, cx, 0};
  double norm = 0;
  for (double v : m) norm += v * v;
  norm = std::sqrt(norm);
  for (double& v : m) v /= norm;
  return 1;
}

// The unit vector minimising v^T M v for a symmetric positive semi-definite 9x9 M: inverse iteration, which
// converges in a few steps because the smallest eigenvalue of these normal equations is far below the next;
// faster than Eigen's SelfAdjointEigenSolver, which remains the fallback (docs/measurements/code-choices.md,
// "MAGSAC++'s solvers").
bool SmallestEigenvector(const Mat9& M, Vec9* v) {
  const double shift = 1e-12 * M.trace();
  const Eigen::LDLT<Mat9> ldlt(M + shift * Mat9::Identity());
  if (ldlt.info() == Eigen::Success) {
    Vec9 x = Vec9::Ones();
    for (int i = 0; i < 4; ++i) {
      x = ldlt.solve(x);
      const double norm = x.norm();
      if (!(norm > 0) || !std::isfinite(norm)) break;
      x /= norm;
      if (i == 3) {
        *v = x;
        return true;
      }
    }
  }
  const Eigen::SelfAdjointEigenSolver<Mat9> eigen(M);
  if (eigen.info() != Eigen::Success) return false;
  *v = eigen.eigenvectors().col(0);
  return true;
}

// The normal equations sum_i w_i^2 a_i a_i^T of the 8-point system, a_i = (x1 x0, x1 y0, x1, y1 x0, y1 y0, y1,
// x0, y0, 1) of points[indices[i]] (w_i = 1 without weights). Each product w^2 a[r] a[c] (r <= c) is summed
// into the lower triangle, whose columns are contiguous in Eigen's column-major storage, so that the inner loop
// vectorises; the upper triangle is then mirrored from it.
__attribute__((target_clones("avx2", "default"))) void NormalEquations(const std::vector<Point>& points,
                                                                       const std::vector<int>& indices, int count,
                                                                       const std::vector<double>* weights, Mat9* M) {
  M->setZero();
  double* m = M->data();
  for (int i = 0; i < count; ++i) {
    const Point& p = points[indices[i]];
    const double a[9] = {p.x1 * p.x0, p.x1 * p.y0, p.x1, p.y1 * p.x0, p.y1 * p.y0, p.y1, p.x0, p.y0, 1.0};
    const double w = weights ? (*weights)[i] : 1.0;
    const double w2 = w * w;
    for (int r = 0; r < 9; ++r) {
      const double ar = w2 * a[r];
      for (int c = r; c < 9; ++c) m[9 * r + c] += ar * a[c];
    }
  }
  for (int c = 1; c < 9; ++c)
    for (int r = 0; r < c; ++r) (*M)(r, c) = (*M)(c, r);
}

// Adds a a^T to the upper triangle of M (the homography's rows; rare: DEGENSAC only).
inline void AccumulateRow(const double (&a)[9], Mat9* M) {
  for (int r = 0; r < 9; ++r)
    for (int c = r; c < 9; ++c) (*M)(r, c) += a[r] * a[c];
}

void SymmetrizeUpper(Mat9* M) {
  for (int r = 1; r < 9; ++r)
    for (int c = 0; c < r; ++c) (*M)(r, c) = (*M)(c, r);
}

}  // namespace

Model ToModel(const Mat3& F) {
  const double norm = F.norm();
  Model m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[3 * r + c] = F(r, c) / norm;
  return m;
}

Mat3 ToMatrix(const Model& m) {
  Mat3 F;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) F(r, c) = m[3 * r + c];
  return F;
}

Mat3 Skew(const Vec3& v) {
  Mat3 s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

bool NormalizedPoints::Normalize() {
  const int n = static_cast<int>(pixels.size());
  double c0x = 0, c0y = 0, c1x = 0, c1y = 0;
  for (const Point& p : pixels) {
    c0x += p.x0;
    c0y += p.y0;
    c1x += p.x1;
    c1y += p.y1;
  }
  c0x /= n, c0y /= n, c1x /= n, c1y /= n;
  double d0 = 0, d1 = 0;
  for (const Point& p : pixels) {
    d0 += std::hypot(p.x0 - c0x, p.y0 - c0y);
    d1 += std::hypot(p.x1 - c1x, p.y1 - c1y);
  }
  d0 /= n, d1 /= n;
  if (!(d0 > 1e-9 && d1 > 1e-9)) return false;
  const double s0 = std::sqrt(2.0) / d0, s1 = std::sqrt(2.0) / d1;
  T0 << s0, 0, -s0 * c0x, 0, s0, -s0 * c0y, 0, 0, 1;
  T1 << s1, 0, -s1 * c1x, 0, s1, -s1 * c1y, 0, 0, 1;
  normalized.resize(n);
  for (int i = 0; i < n; ++i) {
    const Point& p = pixels[i];
    normalized[i] = {s0 * (p.x0 - c0x), s0 * (p.y0 - c0y), s1 * (p.x1 - c1x), s1 * (p.y1 - c1y)};
  }
  return true;
}

int SolveSevenPoint(const NormalizedPoints& points, const SevenPointSample& sample, SevenPointModels* models,
                    bool* stationary) {
  *stationary = false;
  double A[7][9];
  for (int r = 0; r < 7; ++r) {
    const Point& p = points.normalized[sample[r]];
    double* row = A[r];
    row[0] = p.x1 * p.x0, row[1] = p.x1 * p.y0, row[2] = p.x1;
    row[3] = p.y1 * p.x0, row[4] = p.y1 * p.y0, row[5] = p.y1;
    row[6] = p.x0, row[7] = p.y0, row[8] = 1.0;
  }
  int column[9] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  bool permuted = false;
  for (int k = 0; k < 7; ++k) {
    int pivot_row = k, pivot_col = k;
    double pivot = std::abs(A[k][k]);
    for (int r = k + 1; r < 7; ++r) {
      if (std::abs(A[r][k]) > pivot) pivot = std::abs(A[r][k]), pivot_row = r;
    }
    if (pivot < 1e-6) {
      for (int r = k; r < 7; ++r)
        for (int c = k + 1; c < 9; ++c)
          if (std::abs(A[r][c]) > pivot) pivot = std::abs(A[r][c]), pivot_row = r, pivot_col = c;
      // Fewer than 7 independent equations.
      if (pivot < 1e-10) return SolveStationary(points, sample, models, stationary);
    }
    if (pivot_row != k) std::swap(A[k], A[pivot_row]);
    if (pivot_col != k) {
      for (int r = 0; r < 7; ++r) std::swap(A[r][k], A[r][pivot_col]);
      std::swap(column[k], column[pivot_col]);
      permuted = true;
    }
    const double inverse = 1.0 / A[k][k];
    for (int r = k + 1; r < 7; ++r) {
      const double factor = A[r][k] * inverse;
      for (int c = k + 1; c < 9; ++c) A[r][c] -= factor * A[k][c];
    }
  }
  // Both null vectors at once: free variables (x7, x8) = (1, 0) and (0, 1).
  double x[9], y[9];
  x[7] = 1, x[8] = 0, y[7] = 0, y[8] = 1;
  for (int r = 6; r >= 0; --r) {
    double sx = A[r][7], sy = A[r][8];
    for (int c = r + 1; c < 7; ++c) sx += A[r][c] * x[c], sy += A[r][c] * y[c];
    const double inverse = -1.0 / A[r][r];
    x[r] = sx * inverse;
    y[r] = sy * inverse;
  }
  double F1[9], F2[9];
  for (int c = 0; c < 9; ++c) {
    F1[permuted ? column[c] : c] = x[c];
    F2[permuted ? column[c] : c] = y[c];
  }
  // det(F2 + a (F1 - F2)) is a cubic in a: its coefficients from four evaluations.
  double D[9];
  for (int i = 0; i < 9; ++i) D[i] = F1[i] - F2[i];
  auto det_at = [&](double a) {
    double m[9];
    for (int i = 0; i < 9; ++i) m[i] = F2[i] + a * D[i];
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) + m[2] * (m[3] * m[7] - m[4] * m[6]);
  };
  const double p0 = det_at(0), p1 = det_at(1), pm = det_at(-1), p2 = det_at(2);
  const double c0 = p0, c2 = 0.5 * (p1 + pm) - p0, s = 0.5 * (p1 - pm);
  const double c3 = (p2 - c0 - 4 * c2 - 2 * s) / 6.0, c1 = s - c3;
  double roots[3];
  const int num_roots = SolveCubic(c3, c2, c1, c0, roots);
  int count = 0;
  for (int i = 0; i < num_roots; ++i) {
    double normalized[9];
    for (int k = 0; k < 9; ++k) normalized[k] = F2[k] + roots[i] * D[k];
    if (!OrientedConstraintHolds(points, normalized, sample)) continue;
    if (Denormalize(points, normalized, &(*models)[count])) ++count;
  }
  return count;
}

bool FitFundamental(const NormalizedPoints& points, const std::vector<int>& indices, int count,
                    const std::vector<double>* weights, Model* model) {
  if (count < 8) return false;
  Mat9 M;
  NormalEquations(points.normalized, indices, count, weights, &M);
  Vec9 f;
  if (!SmallestEigenvector(M, &f)) return false;
  Mat3 F;
  F << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);
  // Rank 2: remove the smallest singular component, F - (F v) v^T with v the right singular vector of the
  // smallest singular value (closed-form 3x3 eigen-decomposition of F^T F, cheaper than a 3x3 SVD).
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(F.transpose() * F);
  const Vec3 v = eigen.eigenvectors().col(0);
  F -= (F * v) * v.transpose();
  double normalized[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) normalized[3 * r + c] = F(r, c);
  return Denormalize(points, normalized, model);
}

bool FitHomography(const NormalizedPoints& points, const std::vector<int>& indices, int count, Mat3* H) {
  if (count < 4) return false;
  Mat9 M = Mat9::Zero();
  for (int i = 0; i < count; ++i) {
    const Point& p = points.normalized[indices[i]];
    const double a[9] = {0, 0, 0, -p.x0, -p.y0, -1, p.y1 * p.x0, p.y1 * p.y0, p.y1};
    const double b[9] = {p.x0, p.y0, 1, 0, 0, 0, -p.x1 * p.x0, -p.x1 * p.y0, -p.x1};
    AccumulateRow(a, &M);
    AccumulateRow(b, &M);
  }
  SymmetrizeUpper(&M);
  Vec9 h;
  if (!SmallestEigenvector(M, &h)) return false;
  Mat3 Hn;
  Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  *H = points.T1.inverse() * Hn * points.T0;
  return H->allFinite();
}

}  // namespace vmap::internal
