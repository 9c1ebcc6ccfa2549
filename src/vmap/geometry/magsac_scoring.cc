#include "vmap/geometry/magsac_scoring.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace vmap::internal {
namespace {

// The settings of OpenCV 4.6's USAC_MAGSAC preset for F.
constexpr double kSigmaQuantile = 3.64;    // sqrt of the 0.99 quantile of chi^2 with 4 degrees of freedom
constexpr double kMaximumThreshold = 2.5;  // px: residuals beyond it carry no score (sigma_max = 2.5 / 3.64)
constexpr int kIrlsSampleSize = 50;        // points per weighted fit of sigma-consensus++
constexpr int kIrlsRounds = 10;

}  // namespace

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

MagsacScorer::MagsacScorer(const NormalizedPoints& points, double threshold, MagsacStatistics* statistics)
    : points_(points),
      tables_(MagsacTables::Get()),
      statistics_(statistics),
      n_(static_cast<int>(points.pixels.size())) {
  const double max_threshold = std::max(kMaximumThreshold, threshold);
  max_squared_ = max_threshold * max_threshold;
  inv_max_squared_ = 1.0 / max_squared_;
  threshold_squared_ = threshold * threshold;
  columns_.Assign(points.pixels);
  squared_errors_.resize(n_);
}

Score MagsacScorer::Evaluate(const Model& model, double bound, Sprt* sprt) {
  ++statistics_->models_scored;
  const bool use_sprt = sprt && sprt->active();
  const double log_accept = sprt ? sprt->log_accept() : 0.0, log_reject = sprt ? sprt->log_reject() : 0.0;
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
      log_lambda += log_accept;
    } else {
      log_lambda += log_reject;
    }
    if (use_sprt && log_lambda > sprt->log_threshold()) {
      sprt->Rejected(i + 1, score.consistent);
      return Score{};
    }
    if (value + (n_ - 1 - i) < bound) return Score{};
  }
  score.value = value;
  return score;
}

bool MagsacScorer::SigmaConsensus(const Model& model, int min_consistent, RandomStream& random, Model* refined,
                                  Score* score) {
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
      ++statistics_->local_optimizations;
    }
    if (current_score.value > best.value) {
      best = current_score;
      best_model = current;
    }
    if (round == kIrlsRounds) break;
    if (count > kIrlsSampleSize) {
      for (int i = 0; i < kIrlsSampleSize; ++i) {
        const int j = i + random.Uniform(count - i);
        std::swap(indices[i], indices[j]);
        std::swap(weights[i], weights[j]);
      }
      count = kIrlsSampleSize;
    }
    if (!FitFundamental(points_, indices, count, &weights, &current)) break;
  }
  *refined = best_model;
  *score = best;
  return true;
}

}  // namespace vmap::internal
