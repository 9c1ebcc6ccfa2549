#include "vmap/geometry/magsac.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <tuple>

#include <Eigen/Dense>

#include "vmap/geometry/sampson_errors.h"

namespace vmap {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec9 = Eigen::Matrix<double, 9, 1>;

// The settings of OpenCV 4.6's USAC_MAGSAC preset for F.
constexpr int kSampleSize = 7;
constexpr double kSigmaQuantile = 3.64;     // sqrt of the 0.99 quantile of chi^2 with 4 degrees of freedom
constexpr double kMaximumThreshold = 2.5;   // px: residuals beyond it carry no score (sigma_max = 2.5 / 3.64)
constexpr int kIrlsSampleSize = 50;         // points per weighted fit of sigma-consensus++
constexpr int kIrlsRounds = 10;
constexpr int kItersScoredWithoutSprt = 15;
constexpr int kSigmaConsensusEvery = 10;    // every tenth sample's models are refined instead of scored
constexpr int kItersBeforeLocalOptimization = 100;
constexpr int kPolishRounds = 3;
constexpr double kHomographySquaredThreshold = 5.0;  // px^2, DEGENSAC's plane test
constexpr int kPlaneAndParallaxIterations = 100;
// SPRT: model estimation costs about this many point evaluations, and a sample gives this many models.
constexpr double kSprtModelCost = 200.0;
constexpr double kSprtModelsPerSample = 2.0;
constexpr int kAbandonPollEvery = 32;

// MAGSAC++ marginalises the residual over noise scales sigma in [0, sigma_max]; with 4 degrees of freedom its
// loss and its IRLS weight are closed forms in the incomplete gamma functions Gamma(1.5, x) and gamma(2.5, x),
// x = r^2 / (2 sigma_max^2), which reaches k^2 / 2 at the maximum threshold. Both are tabulated once by
// u = r^2 / r_max^2, which does not depend on the threshold; the score of a point is 1 - loss / max loss.
class MagsacTables {
 public:
  static constexpr int kSize = 4096;

  static const MagsacTables& Get() {
    static const MagsacTables tables;
    return tables;
  }
  float Quality(double u) const { return quality_[Index(u)]; }
  double Weight(double u) const { return weight_[Index(u)]; }

 private:
  static int Index(double u) { return std::min(kSize, static_cast<int>(u * kSize + 0.5)); }

  MagsacTables() {
    const double sqrt_pi = std::sqrt(M_PI);
    auto upper_gamma_1_5 = [&](double x) {  // Gamma(1.5, x) = Gamma(0.5, x) / 2 + sqrt(x) e^-x
      return 0.5 * sqrt_pi * std::erfc(std::sqrt(x)) + std::sqrt(x) * std::exp(-x);
    };
    auto lower_gamma_2_5 = [&](double x) {  // gamma(2.5, x) = Gamma(2.5) - 1.5 Gamma(1.5, x) - x^1.5 e^-x
      return 0.75 * sqrt_pi - 1.5 * upper_gamma_1_5(x) - x * std::sqrt(x) * std::exp(-x);
    };
    const double x_max = kSigmaQuantile * kSigmaQuantile / 2.0;
    const double gamma_at_k = upper_gamma_1_5(x_max);
    std::array<double, kSize + 1> loss{};
    double max_loss = 0.0;
    for (int i = 0; i <= kSize; ++i) {
      const double x = x_max * i / kSize;
      loss[i] = 0.5 * lower_gamma_2_5(x) + 0.5 * x * (upper_gamma_1_5(x) - gamma_at_k);
      max_loss = std::max(max_loss, loss[i]);
      weight_[i] = std::max(0.0, upper_gamma_1_5(x) - gamma_at_k);
    }
    for (int i = 0; i <= kSize; ++i) quality_[i] = static_cast<float>(1.0 - loss[i] / max_loss);
  }

  std::array<float, kSize + 1> quality_{};
  std::array<double, kSize + 1> weight_{};
};

using internal::Model;
using internal::Point;
using internal::PointColumns;
using internal::SquaredSampson;
using internal::SquaredSampsonErrors;

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

// Higher is better; a model with no score has value -1.
struct Score {
  double value = -1.0;
  int inliers = 0;     // points within the threshold: what S counts
  int consistent = 0;  // points within the maximum threshold: SPRT's notion of support
};

// SPRT state: epsilon = support of the best model, delta = support of bad models (estimated).
struct Sprt {
  bool active = false;
  double delta = 0.01;
  double log_accept = 0, log_reject = 0, log_threshold = 0;
  double rejected_tested = 0, rejected_consistent = 0;
  int rejected_since_update = 0;
};

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

}  // namespace

// Everything the sample loop carries from one sample to the next, as it was when the loop stopped early, and
// what the run was given, so that a run resumed from it can be checked to be the same run.
struct MagsacCheckpoint {
  int num_points = 0;
  std::uint64_t points_fingerprint = 0;
  double threshold = 0, confidence = 0;
  int max_iterations = 0, seed = 0;

  int iterations = 0;
  std::uint64_t random_draws = 0;
  bool local_optimization_ran = false;
  bool have_best = false;
  internal::Model best{};
  Score best_score;
  Sprt sprt;
  MagsacStatistics statistics;
};

namespace {

// One robust estimation; every member is scratch space reused across the loop.
class Estimator {
 public:
  Estimator(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
            const VerifierOptions& options, const EarlyStop& early_stop)
      : options_(options),
        tables_(MagsacTables::Get()),
        rng_(static_cast<std::uint32_t>(options.seed)),
        n_(static_cast<int>(points0.size())) {
    const double max_threshold = std::max(kMaximumThreshold, options.threshold);
    max_squared_ = max_threshold * max_threshold;
    inv_max_squared_ = 1.0 / max_squared_;
    threshold_squared_ = options.threshold * options.threshold;

    // The points are visited in a random order, so that SPRT sees a fair sample of them first. The order is
    // drawn from the points sorted by coordinates, so that the result does not depend on the order they come
    // in: a link verified again from its stored correspondences (verified ones first) continues exactly the
    // run that decided it.
    order_.resize(n_);
    for (int i = 0; i < n_; ++i) order_[i] = i;
    std::sort(order_.begin(), order_.end(), [&](int a, int b) {
      const cv::Point2f &a0 = points0[a], &b0 = points0[b], &a1 = points1[a], &b1 = points1[b];
      return std::tie(a0.x, a0.y, a1.x, a1.y) < std::tie(b0.x, b0.y, b1.x, b1.y);
    });
    for (int i = n_ - 1; i > 0; --i) std::swap(order_[i], order_[Uniform(i + 1)]);
    points_.resize(n_);
    for (int i = 0; i < n_; ++i) {
      const int k = order_[i];
      points_[i] = {points0[k].x, points0[k].y, points1[k].x, points1[k].y};
    }
    columns_.Assign(points_);
    squared_errors_.resize(n_);
    abandon_ = early_stop.abandon;
    resume_from_ = early_stop.resume_from;
    for (int target : early_stop.min_inliers) {
      const int needed = SamplesToSettle(static_cast<double>(target) / n_, options.confidence, options.max_iterations);
      targets_.push_back({target, std::min(needed, options.max_samples_to_reject)});
    }
  }

  FundamentalResult Run(MagsacStatistics* statistics);

 private:
  struct Target {
    int min_inliers;
    int samples_to_fail;
  };

  int Uniform(int bound) {
    ++random_draws_;
    return static_cast<int>((static_cast<std::uint64_t>(rng_()) * bound) >> 32);
  }
  // FNV-1a over the points in visiting order: a resumed run must be given the points its checkpoint was.
  std::uint64_t PointsFingerprint() const;
  std::shared_ptr<const MagsacCheckpoint> Checkpoint(int iterations, bool local_optimization_ran) const;
  void Resume(const MagsacCheckpoint& checkpoint, int* iterations, bool* local_optimization_ran);

  bool Normalize();
  int SolveMinimal(const std::array<int, kSampleSize>& sample, std::array<Model, 3>* models);
  bool Denormalize(const double* normalized, Model* model) const;
  int SolveStationary(const std::array<int, kSampleSize>& sample, std::array<Model, 3>* models);
  bool stationary_sample_ = false;  // the last SolveMinimal's sample had not moved (SolveStationary)
  bool OrientedConstraintHolds(const double* normalized_model, const std::array<int, kSampleSize>& sample) const;
  bool FitFundamental(const std::vector<int>& indices, int count, const std::vector<double>* weights, Model* model);
  bool FitHomography(const std::vector<int>& indices, int count, Mat3* H);
  Score Evaluate(const Model& model, double bound, bool use_sprt);
  Score FullScore(const Model& model) { return Evaluate(model, -1.0, false); }
  bool SigmaConsensus(const Model& model, int min_consistent, Model* refined, Score* score);
  bool RecoverIfDegenerate(const std::array<int, kSampleSize>& sample, const Model& model, Model* recovered,
                           Score* recovered_score);
  void UpdateSprt();
  bool Settled(int iterations) const;
  // Samples the confidence criterion asks for, given the best model's inliers.
  int SamplesForBestModel() const {
    return SamplesToSettle(static_cast<double>(best_score_.inliers) / n_, options_.confidence,
                           options_.max_iterations);
  }
  bool PassesAllSettledTargets(int inliers) const;

  const VerifierOptions& options_;
  const MagsacTables& tables_;
  std::mt19937 rng_;
  std::uint64_t random_draws_ = 0;  // rng_'s outputs used so far (a checkpoint's place in the random stream)
  const int n_;
  double max_squared_ = 0, inv_max_squared_ = 0, threshold_squared_ = 0;
  std::vector<int> order_;
  std::vector<Point> points_;      // pixels, in visiting order
  PointColumns columns_;           // the same, column by column
  std::vector<double> squared_errors_;  // scratch for SquaredSampsonErrors
  std::vector<Point> normalized_;  // Hartley-normalised copies for the solvers
  Mat3 T0_, T1_;                   // normalised = T * pixel, per image
  std::vector<Target> targets_;
  std::function<bool()> abandon_;
  std::shared_ptr<const MagsacCheckpoint> resume_from_;

  Model best_{};
  Score best_score_;
  bool have_best_ = false;

  Sprt sprt_;

  std::vector<int> scratch_indices_;
  std::vector<double> scratch_weights_;
  MagsacStatistics stats_;
};

bool Estimator::Normalize() {
  double c0x = 0, c0y = 0, c1x = 0, c1y = 0;
  for (const Point& p : points_) {
    c0x += p.x0;
    c0y += p.y0;
    c1x += p.x1;
    c1y += p.y1;
  }
  c0x /= n_, c0y /= n_, c1x /= n_, c1y /= n_;
  double d0 = 0, d1 = 0;
  for (const Point& p : points_) {
    d0 += std::hypot(p.x0 - c0x, p.y0 - c0y);
    d1 += std::hypot(p.x1 - c1x, p.y1 - c1y);
  }
  d0 /= n_, d1 /= n_;
  if (!(d0 > 1e-9 && d1 > 1e-9)) return false;
  const double s0 = std::sqrt(2.0) / d0, s1 = std::sqrt(2.0) / d1;
  T0_ << s0, 0, -s0 * c0x, 0, s0, -s0 * c0y, 0, 0, 1;
  T1_ << s1, 0, -s1 * c1x, 0, s1, -s1 * c1y, 0, 0, 1;
  normalized_.resize(n_);
  for (int i = 0; i < n_; ++i) {
    const Point& p = points_[i];
    normalized_[i] = {s0 * (p.x0 - c0x), s0 * (p.y0 - c0y), s1 * (p.x1 - c1x), s1 * (p.y1 - c1y)};
  }
  return true;
}

// The 7-point algorithm, in normalised coordinates: the two-dimensional null space of the 7x9 epipolar system
// (Gaussian elimination, partial pivoting on the first seven columns, full pivoting when one has no pivot),
// then the real roots a of det(a F1 + (1 - a) F2) = 0. Models breaking the oriented epipolar constraint are
// dropped before they are brought back to pixels.
int Estimator::SolveMinimal(const std::array<int, kSampleSize>& sample, std::array<Model, 3>* models) {
  double A[7][9];
  for (int r = 0; r < 7; ++r) {
    const Point& p = normalized_[sample[r]];
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
      if (pivot < 1e-10) return SolveStationary(sample, models);  // fewer than 7 independent equations
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
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
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
    if (!OrientedConstraintHolds(normalized, sample)) continue;
    if (Denormalize(normalized, &(*models)[count])) ++count;
  }
  return count;
}

// A sample whose points did not move (a frame repeated, a robot standing still) leaves the epipolar system
// rank-deficient: every F = [e]x fits it. OpenCV's USAC returns such an F with every unmoved point an inlier,
// and Algorithm 1 depends on it (a repeated frame must pass, not become a key image); so does this: the
// epipole is put at the sample's centroid. Any other degenerate sample
// yields no model.
int Estimator::SolveStationary(const std::array<int, kSampleSize>& sample, std::array<Model, 3>* models) {
  constexpr double kUnmoved = 1e-6;  // pixels
  double cx = 0, cy = 0;
  for (int i : sample) {
    const Point& p = points_[i];
    if (std::abs(p.x1 - p.x0) > kUnmoved || std::abs(p.y1 - p.y0) > kUnmoved) return 0;
    cx += p.x0 / kSampleSize;
    cy += p.y0 / kSampleSize;
  }
  stationary_sample_ = true;
  // [e]x for e = (cx, cy, 1), in pixels, scaled to unit norm as Denormalize does.
  Model& m = (*models)[0];
  m = {0, -1, cy, 1, 0, -cx, -cy, cx, 0};
  double norm = 0;
  for (double v : m) norm += v * v;
  norm = std::sqrt(norm);
  for (double& v : m) v /= norm;
  return 1;
}

// F in pixels from F in normalised coordinates: T1^T Fn T0 with T = [s 0 tx; 0 s ty; 0 0 1], scaled to unit norm.
bool Estimator::Denormalize(const double* fn, Model* model) const {
  const double s0 = T0_(0, 0), a0 = T0_(0, 2), b0 = T0_(1, 2);
  const double s1 = T1_(0, 0), a1 = T1_(0, 2), b1 = T1_(1, 2);
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
bool Estimator::OrientedConstraintHolds(const double* m, const std::array<int, kSampleSize>& sample) const {
  double e[3] = {m[1] * m[8] - m[2] * m[7], m[2] * m[6] - m[0] * m[8], m[0] * m[7] - m[1] * m[6]};  // row0 x row2
  if (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] < 1e-20) {  // rows 0 and 2 parallel: use rows 1 and 2
    e[0] = m[4] * m[8] - m[5] * m[7], e[1] = m[5] * m[6] - m[3] * m[8], e[2] = m[3] * m[7] - m[4] * m[6];
  }
  double first_sign = 0;
  for (int i = 0; i < kSampleSize; ++i) {
    const Point& p = normalized_[sample[i]];
    const double l0 = m[0] * p.x1 + m[3] * p.y1 + m[6], l1 = m[1] * p.x1 + m[4] * p.y1 + m[7],
                 l2 = m[2] * p.x1 + m[5] * p.y1 + m[8];
    // (e x x0) . l with x0 = (x, y, 1)
    const double c0 = e[1] - e[2] * p.y0, c1 = e[2] * p.x0 - e[0], c2 = e[0] * p.y0 - e[1] * p.x0;
    const double sign = c0 * l0 + c1 * l1 + c2 * l2;
    if (i == 0) first_sign = sign;
    else if (sign * first_sign < 0) return false;
  }
  return true;
}

// The unit vector minimising v^T M v for a symmetric positive semi-definite 9x9 M: inverse iteration, which
// converges in a few steps because the smallest eigenvalue of these normal equations is far below the next;
// measured 3x faster than Eigen's SelfAdjointEigenSolver, which remains the fallback.
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

// Weighted normalised 8-point algorithm (rows scaled by the weights), rank 2 enforced.
bool Estimator::FitFundamental(const std::vector<int>& indices, int count, const std::vector<double>* weights,
                               Model* model) {
  if (count < 8) return false;
  Mat9 M;
  NormalEquations(normalized_, indices, count, weights, &M);
  Vec9 f;
  if (!SmallestEigenvector(M, &f)) return false;
  Mat3 F;
  F << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);
  // Rank 2: remove the smallest singular component, F - (F v) v^T with v the right singular vector of the
  // smallest singular value (closed-form 3x3 eigen-decomposition of F^T F, ~10x cheaper than a 3x3 SVD).
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(F.transpose() * F);
  const Vec3 v = eigen.eigenvectors().col(0);
  F -= (F * v) * v.transpose();
  double normalized[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) normalized[3 * r + c] = F(r, c);
  return Denormalize(normalized, model);
}

// Normalised DLT for x1 ~ H x0 (pixels).
bool Estimator::FitHomography(const std::vector<int>& indices, int count, Mat3* H) {
  if (count < 4) return false;
  Mat9 M = Mat9::Zero();
  for (int i = 0; i < count; ++i) {
    const Point& p = normalized_[indices[i]];
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
  *H = T1_.inverse() * Hn * T0_;
  return H->allFinite();
}

// The MAGSAC++ score of a model over the points in visiting order. Stops (and returns value -1) as soon as the
// model can no longer beat `bound`, or when SPRT rejects it.
Score Estimator::Evaluate(const Model& model, double bound, bool use_sprt) {
  ++stats_.models_scored;
  use_sprt = use_sprt && sprt_.active;
  Score score;
  double value = 0, log_lambda = 0;
  // Errors a block at a time: SPRT rejects most models within the first few dozen points.
  constexpr int kBlock = 16;
  double* errors = squared_errors_.data();
  for (int i = 0; i < n_; ++i) {
    if (i % kBlock == 0) SquaredSampsonErrors(model, columns_, i, std::min(n_, i + kBlock), errors);
    const double r2 = errors[i % kBlock];
    if (r2 < max_squared_) {
      value += tables_.Quality(r2 * inv_max_squared_);
      ++score.consistent;
      if (r2 < threshold_squared_) ++score.inliers;
      log_lambda += sprt_.log_accept;
    } else {
      log_lambda += sprt_.log_reject;
    }
    if (use_sprt && log_lambda > sprt_.log_threshold) {
      sprt_.rejected_tested += i + 1;
      sprt_.rejected_consistent += score.consistent;
      if (++sprt_.rejected_since_update >= 50) UpdateSprt();
      return Score{};
    }
    if (value + (n_ - 1 - i) < bound) return Score{};
  }
  score.value = value;
  return score;
}

// Matas & Chum (2008): the decision threshold A solves A = t_M C / m_S + 1 + ln A, with C the expected
// information per point; it is recomputed when epsilon (the best model) or delta (bad models) change.
void Estimator::UpdateSprt() {
  if (sprt_.rejected_tested > 0) {
    sprt_.delta = std::clamp(sprt_.rejected_consistent / sprt_.rejected_tested, 0.001, 0.5);
  }
  sprt_.rejected_since_update = 0;
  const double epsilon = have_best_ ? static_cast<double>(best_score_.inliers) / n_ : 0.0;
  const double delta = sprt_.delta;
  sprt_.active = have_best_ && epsilon > 1.5 * delta && epsilon < 1.0;
  if (!sprt_.active) return;
  sprt_.log_accept = std::log(delta / epsilon);
  sprt_.log_reject = std::log((1 - delta) / (1 - epsilon));
  const double C = (1 - delta) * sprt_.log_reject + delta * sprt_.log_accept;
  const double K = kSprtModelCost * C / kSprtModelsPerSample + 1;
  double A = K;
  for (int i = 0; i < 10; ++i) A = K + std::log(A);
  sprt_.log_threshold = std::log(A);
}

// sigma-consensus++: iteratively re-weighted least squares with MAGSAC++ weights on the points within the
// maximum threshold (a random 50 of them per round, as OpenCV does), keeping the best-scoring model of the
// rounds. Each pass over the points both scores the current model and weighs the points for the next fit.
bool Estimator::SigmaConsensus(const Model& model, int min_consistent, Model* refined, Score* score) {
  std::vector<int>& indices = scratch_indices_;
  std::vector<double>& weights = scratch_weights_;
  indices.resize(n_);
  weights.resize(n_);
  Model current = model;
  Score best;
  Model best_model = model;
  for (int round = 0; round <= kIrlsRounds; ++round) {
    Score current_score;
    double value = 0;
    int count = 0;
    SquaredSampsonErrors(current, columns_, 0, n_, squared_errors_.data());
    for (int i = 0; i < n_; ++i) {
      const double r2 = squared_errors_[i];
      if (r2 < max_squared_) {
        const double u = r2 * inv_max_squared_;
        value += tables_.Quality(u);
        if (r2 < threshold_squared_) ++current_score.inliers;
        indices[count] = i;
        weights[count++] = tables_.Weight(u);
      }
    }
    current_score.value = value;
    current_score.consistent = count;
    if (round == 0) {
      if (count < min_consistent) return false;  // cannot beat the best model's inliers
      ++stats_.local_optimizations;
    }
    if (current_score.value > best.value) {
      best = current_score;
      best_model = current;
    }
    if (round == kIrlsRounds) break;
    if (count > kIrlsSampleSize) {
      for (int i = 0; i < kIrlsSampleSize; ++i) {
        const int j = i + Uniform(count - i);
        std::swap(indices[i], indices[j]);
        std::swap(weights[i], weights[j]);
      }
      count = kIrlsSampleSize;
    }
    if (!FitFundamental(indices, count, &weights, &current)) break;
  }
  *refined = best_model;
  *score = best;
  return true;
}

// DEGENSAC (Chum, Werner & Matas 2005): when five of the seven sample points fit one homography H, the 7-point
// model may explain the plane only. Then F is re-estimated as [e']_x H with the epipole from two off-plane
// points (plane and parallax), by a small RANSAC. Returns whether the sample was degenerate.
bool Estimator::RecoverIfDegenerate(const std::array<int, kSampleSize>& sample, const Model& model,
                                    Model* recovered, Score* recovered_score) {
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
      const Point& p = points_[sample[triplet[k]]];
      const Vec3 x0(p.x0, p.y0, 1.0), x1(p.x1, p.y1, 1.0);
      const Vec3 x1_e1 = x1.cross(e1);
      b(k) = x1.cross(A * x0).dot(x1_e1) / x1_e1.squaredNorm();
      M.row(k) = x0.transpose();
    }
    if (std::abs(M.determinant()) < 1e-12) continue;
    Mat3 H = A - e1 * (M.inverse() * b).transpose();
    int off_plane = 0;
    for (int s = 0; s < kSampleSize && off_plane <= 2; ++s) {
      if (squared_transfer_error(H, points_[sample[s]]) > kHomographySquaredThreshold) ++off_plane;
    }
    if (off_plane > 2) continue;
    degenerate = true;
    // Refit H on all the points it explains, then search the epipole with pairs of points off the plane.
    std::vector<int> on_plane;
    std::vector<char> off(n_);
    for (int i = 0; i < n_; ++i) {
      if (squared_transfer_error(H, points_[i]) < kHomographySquaredThreshold) on_plane.push_back(i);
    }
    Mat3 refined_H;
    if (FitHomography(on_plane, static_cast<int>(on_plane.size()), &refined_H)) H = refined_H;
    for (int i = 0; i < n_; ++i) off[i] = squared_transfer_error(H, points_[i]) > kHomographySquaredThreshold;
    int max_iterations = kPlaneAndParallaxIterations;
    for (int it = 0; it < max_iterations; ++it) {
      const int a = Uniform(n_);
      int c = Uniform(n_);
      while (c == a && n_ > 1) c = Uniform(n_);
      if (!off[a] || !off[c]) continue;
      const Point& pa = points_[a];
      const Point& pc = points_[c];
      const Vec3 la = Vec3(pa.x1, pa.y1, 1.0).cross(H * Vec3(pa.x0, pa.y0, 1.0));
      const Vec3 lc = Vec3(pc.x1, pc.y1, 1.0).cross(H * Vec3(pc.x0, pc.y0, 1.0));
      const Mat3 candidate = Skew(la.cross(lc)) * H;
      if (!candidate.allFinite() || candidate.norm() == 0) continue;
      const Model candidate_model = ToModel(candidate);
      const Score score = Evaluate(candidate_model, recovered_score->value, false);
      if (score.value > recovered_score->value) {
        *recovered_score = score;
        *recovered = candidate_model;
        const double w = static_cast<double>(score.inliers) / n_;
        const double needed = std::log(0.05) / std::log1p(-w * w);
        if (std::isfinite(needed) && needed < max_iterations) max_iterations = static_cast<int>(needed);
      }
    }
  }
  return degenerate;
}

std::uint64_t Estimator::PointsFingerprint() const {
  std::uint64_t hash = 14695981039346656037ull;
  for (const Point& p : points_) {
    for (double v : {p.x0, p.y0, p.x1, p.y1}) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      hash = (hash ^ bits) * 1099511628211ull;
    }
  }
  return hash;
}

std::shared_ptr<const MagsacCheckpoint> Estimator::Checkpoint(int iterations, bool local_optimization_ran) const {
  auto checkpoint = std::make_shared<MagsacCheckpoint>();
  checkpoint->num_points = n_;
  checkpoint->points_fingerprint = PointsFingerprint();
  checkpoint->threshold = options_.threshold;
  checkpoint->confidence = options_.confidence;
  checkpoint->max_iterations = options_.max_iterations;
  checkpoint->seed = options_.seed;
  checkpoint->iterations = iterations;
  checkpoint->random_draws = random_draws_;
  checkpoint->local_optimization_ran = local_optimization_ran;
  checkpoint->have_best = have_best_;
  checkpoint->best = best_;
  checkpoint->best_score = best_score_;
  checkpoint->sprt = sprt_;
  checkpoint->statistics = stats_;
  return checkpoint;
}

void Estimator::Resume(const MagsacCheckpoint& checkpoint, int* iterations, bool* local_optimization_ran) {
  if (checkpoint.num_points != n_ || checkpoint.points_fingerprint != PointsFingerprint() ||
      checkpoint.threshold != options_.threshold || checkpoint.confidence != options_.confidence ||
      checkpoint.max_iterations != options_.max_iterations || checkpoint.seed != options_.seed ||
      checkpoint.random_draws < random_draws_) {
    throw std::logic_error("EstimateFundamentalMagsac: resumed with other points or options than its checkpoint's");
  }
  rng_.discard(checkpoint.random_draws - random_draws_);
  random_draws_ = checkpoint.random_draws;
  *iterations = checkpoint.iterations;
  *local_optimization_ran = checkpoint.local_optimization_ran;
  have_best_ = checkpoint.have_best;
  best_ = checkpoint.best;
  best_score_ = checkpoint.best_score;
  sprt_ = checkpoint.sprt;
  stats_ = checkpoint.statistics;
  stats_.stopped_early = false;
}

bool Estimator::Settled(int iterations) const {
  if (targets_.empty()) return false;
  for (const Target& target : targets_) {
    const bool passed = have_best_ && best_score_.inliers >= target.min_inliers;
    const bool failed = target.min_inliers > n_ || iterations >= target.samples_to_fail;
    if (!passed && !failed) return false;
  }
  return true;
}

bool Estimator::PassesAllSettledTargets(int inliers) const {
  for (const Target& target : targets_) {
    if (best_score_.inliers >= target.min_inliers && inliers < target.min_inliers) return false;
  }
  return true;
}

FundamentalResult Estimator::Run(MagsacStatistics* statistics) {
  FundamentalResult result;
  if (n_ < std::max(kSampleSize, options_.min_matches) || !Normalize()) return result;

  int max_iterations = options_.max_iterations;
  bool local_optimization_ran = false;
  bool stopped_early = false;
  std::array<int, kSampleSize> sample{};
  std::array<Model, 3> models{};
  auto update_best = [&](const Model& model, const Score& score) {
    best_ = model;
    best_score_ = score;
    have_best_ = true;
    UpdateSprt();
    max_iterations = SamplesForBestModel();
  };

  int iterations = 0;
  if (resume_from_) {
    Resume(*resume_from_, &iterations, &local_optimization_ran);
    if (have_best_) max_iterations = SamplesForBestModel();
  }
  for (; iterations < max_iterations; ++iterations) {
    if (Settled(iterations)) {
      stopped_early = true;
      break;
    }
    if (abandon_ && iterations % kAbandonPollEvery == 0 && abandon_()) {
      stats_.iterations = iterations;
      if (statistics) *statistics = stats_;
      result.abandoned = true;
      return result;
    }
    for (int k = 0; k < kSampleSize; ++k) {
      int index;
      do index = Uniform(n_);
      while (std::find(sample.begin(), sample.begin() + k, index) != sample.begin() + k);
      sample[k] = index;
    }
    stationary_sample_ = false;
    const int num_models = SolveMinimal(sample, &models);
    const bool refine_samples = iterations >= kItersScoredWithoutSprt && iterations % kSigmaConsensusEvery == 0;
    for (int m = 0; m < num_models; ++m) {
      Model model = models[m];
      Score score;
      if (iterations < kItersScoredWithoutSprt) {
        score = Evaluate(model, best_score_.value, false);
      } else if (refine_samples) {
        if (Evaluate(model, -1.0, true).value < 0) continue;  // SPRT-rejected
        if (!SigmaConsensus(model, best_score_.inliers, &model, &score)) continue;
      } else {
        score = Evaluate(model, best_score_.value, true);
      }
      if (!(score.value > best_score_.value)) continue;
      Model recovered;
      Score recovered_score;
      // A stationary sample's model is the degenerate case itself (H = I explains every point): no plane and
      // parallax to recover it from.
      if (!stationary_sample_ && RecoverIfDegenerate(sample, model, &recovered, &recovered_score)) {
        if (!(recovered_score.value > best_score_.value)) continue;
        update_best(recovered, recovered_score);
      } else {
        update_best(model, score);
      }
      if (iterations >= kItersBeforeLocalOptimization && !refine_samples) {
        local_optimization_ran = true;
        Model refined;
        Score refined_score;
        if (SigmaConsensus(best_, best_score_.inliers, &refined, &refined_score) &&
            refined_score.value > best_score_.value) {
          update_best(refined, refined_score);
        }
      }
    }
    if (have_best_ && !local_optimization_ran && iterations >= kItersBeforeLocalOptimization) {
      local_optimization_ran = true;
      Model refined;
      Score refined_score;
      if (SigmaConsensus(best_, best_score_.inliers, &refined, &refined_score) &&
          refined_score.value > best_score_.value) {
        update_best(refined, refined_score);
      }
    }
  }
  stats_.iterations = iterations;
  stats_.stopped_early = stopped_early;
  if (stopped_early) result.checkpoint = Checkpoint(iterations, local_optimization_ran);
  if (!have_best_) {
    if (statistics) *statistics = stats_;
    return result;
  }

  // Final polish: least squares on the inliers, kept while the score does not get worse; a decision settled
  // as passed stays passed.
  std::vector<int>& inliers = scratch_indices_;
  inliers.resize(n_);
  Model current = best_;
  for (int round = 0; round < kPolishRounds; ++round) {
    int count = 0;
    for (int i = 0; i < n_; ++i) {
      if (SquaredSampson(current, points_[i]) < threshold_squared_) inliers[count++] = i;
    }
    Model fitted;
    if (!FitFundamental(inliers, count, nullptr, &fitted)) break;
    const Score score = FullScore(fitted);
    if (score.value < best_score_.value || !PassesAllSettledTargets(score.inliers)) break;
    const bool small_change = std::abs(score.inliers - best_score_.inliers) < 0.05 * best_score_.inliers;
    best_ = fitted;
    best_score_ = score;
    current = fitted;
    if (small_change) break;
  }

  result.inlier_mask.assign(n_, 0);
  for (int i = 0; i < n_; ++i) {
    if (SquaredSampson(best_, points_[i]) < threshold_squared_) {
      result.inlier_mask[order_[i]] = 1;
      ++result.num_inliers;
    }
  }
  if (statistics) *statistics = stats_;
  if (result.num_inliers < options_.min_matches) {
    result.inlier_mask.clear();
    result.num_inliers = 0;
    return result;
  }
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) result.F(r, c) = best_[3 * r + c];
  result.success = true;
  return result;
}

}  // namespace

int SamplesToSettle(double inlier_ratio, double confidence, int max_iterations) {
  if (inlier_ratio >= 1.0) return 1;
  if (!(inlier_ratio > 0.0)) return max_iterations;
  const double all_inlier = std::pow(inlier_ratio, kSampleSize);
  const double needed = std::ceil(std::log1p(-confidence) / std::log1p(-all_inlier));
  if (!std::isfinite(needed) || needed >= max_iterations) return max_iterations;
  return std::max(1, static_cast<int>(needed));
}

FundamentalResult EstimateFundamentalMagsac(const std::vector<cv::Point2f>& points0,
                                            const std::vector<cv::Point2f>& points1, const VerifierOptions& options,
                                            const EarlyStop& early_stop, MagsacStatistics* statistics) {
  CV_Assert(points0.size() == points1.size());
  Estimator estimator(points0, points1, options, early_stop);
  return estimator.Run(statistics);
}

}  // namespace vmap
