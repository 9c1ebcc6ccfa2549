#pragma once
// The robust estimation loop of vmap's MAGSAC++ (magsac.cc), apart from any model: uniform minimal samples,
// SPRT (Matas & Chum 2008) rejecting bad models after a few points, the stop (the confidence criterion of the
// best model, or every caller's decision settled), and the state a stopped loop resumes from. What a model is,
// how it is solved from a sample, scored and refined, is the Problem's (magsac.cc: the fundamental matrix with
// the MAGSAC++ score). Internal to geometry/.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/magsac.h"

namespace vmap::internal {

// The random stream of one estimation, with the count of outputs used (a checkpoint's place in the stream).
class RandomStream {
 public:
  explicit RandomStream(std::uint32_t seed) : rng_(seed) {}

  // Uniform in [0, bound).
  int Uniform(int bound) {
    ++draws_;
    return static_cast<int>((static_cast<std::uint64_t>(rng_()) * bound) >> 32);
  }
  std::uint64_t draws() const { return draws_; }
  // Moves on to `draws` outputs used (no fewer than now).
  void SkipTo(std::uint64_t draws) {
    rng_.discard(draws - draws_);
    draws_ = draws;
  }

 private:
  std::mt19937 rng_;
  std::uint64_t draws_ = 0;
};

// Higher is better; a model with no score has value -1.
struct Score {
  double value = -1.0;
  int inliers = 0;     // points within the threshold: what S counts
  int consistent = 0;  // points within the maximum threshold: SPRT's notion of support
};

// SPRT's state: epsilon = the best model's support, delta = bad models' support (estimated from the models it
// rejected). The scorer asks it about each point (LogLikelihoodRatio) and reports each rejection (Rejected).
class Sprt {
 public:
  bool active() const { return active_; }
  double log_accept() const { return log_accept_; }
  double log_reject() const { return log_reject_; }
  double log_threshold() const { return log_threshold_; }

  // The best model changed: its inlier ratio is the new epsilon.
  void Update(double epsilon) {
    epsilon_ = epsilon;
    Recompute();
  }
  // A model was rejected after `tested` points, `consistent` of them within the maximum threshold.
  void Rejected(int tested, int consistent) {
    rejected_tested_ += tested;
    rejected_consistent_ += consistent;
    if (++rejected_since_update_ >= kRejectionsPerUpdate) Recompute();
  }

 private:
  // Model estimation costs about this many point evaluations, and a sample gives this many models.
  static constexpr double kModelCost = 200.0;
  static constexpr double kModelsPerSample = 2.0;
  static constexpr int kRejectionsPerUpdate = 50;

  // The decision threshold A solves A = t_M C / m_S + 1 + ln A, with C the expected information per point; it
  // is recomputed when epsilon (the best model) or delta (bad models) change.
  void Recompute() {
    if (rejected_tested_ > 0) delta_ = std::clamp(rejected_consistent_ / rejected_tested_, 0.001, 0.5);
    rejected_since_update_ = 0;
    active_ = epsilon_ > 1.5 * delta_ && epsilon_ < 1.0;
    if (!active_) return;
    log_accept_ = std::log(delta_ / epsilon_);
    log_reject_ = std::log((1 - delta_) / (1 - epsilon_));
    const double C = (1 - delta_) * log_reject_ + delta_ * log_accept_;
    const double K = kModelCost * C / kModelsPerSample + 1;
    double A = K;
    for (int i = 0; i < 10; ++i) A = K + std::log(A);
    log_threshold_ = std::log(A);
  }

  bool active_ = false;
  double epsilon_ = 0.0;  // 0 before there is a best model
  double delta_ = 0.01;
  double log_accept_ = 0, log_reject_ = 0, log_threshold_ = 0;
  double rejected_tested_ = 0, rejected_consistent_ = 0;
  int rejected_since_update_ = 0;
};

// Samples of kSampleSize that must be drawn to find, with the given confidence, an all-inlier sample when a
// share `inlier_ratio` of the points are inliers; at most max_iterations (also when the ratio is 0).
template <int kSampleSize>
int SamplesNeeded(double inlier_ratio, double confidence, int max_iterations) {
  if (inlier_ratio >= 1.0) return 1;
  if (!(inlier_ratio > 0.0)) return max_iterations;
  const double all_inlier = std::pow(inlier_ratio, kSampleSize);
  const double needed = std::ceil(std::log1p(-confidence) / std::log1p(-all_inlier));
  if (!std::isfinite(needed) || needed >= max_iterations) return max_iterations;
  return std::max(1, static_cast<int>(needed));
}

// A caller's decision, "a model with at least min_inliers inliers?": yes once the best model has them, no once
// samples_to_fail samples were drawn without.
struct LoopTarget {
  int min_inliers;
  int samples_to_fail;
};

// The schedule of OpenCV 4.6's USAC_MAGSAC preset.
struct LoopSettings {
  double confidence = 0.99;
  int max_iterations = 10000;
  int scored_without_sprt = 15;  // the first samples' models are scored in full
  int refine_every = 10;         // then every tenth sample's models are refined instead of scored
  // Samples before the best model is refined (once, then each new best model).
  int before_local_optimization = 100;
  int abandon_poll_every = 32;
};

// Everything the loop carries from one sample to the next: a stopped loop goes on from it.
template <typename Model>
struct LoopState {
  int iterations = 0;
  bool local_optimization_ran = false;
  bool have_best = false;
  Model best{};
  Score best_score;
  Sprt sprt;
  MagsacStatistics statistics;  // the Problem counts models scored and local optimisations into it
};

enum class LoopEnd {
  kConfident,  // the confidence criterion of the best model (or max_iterations) was met
  kSettled,    // every target was settled first
  kAbandoned,  // `abandon` returned true
};

// Runs the loop from `state` (fresh, or as a stopped loop left it). Problem provides:
//   Model; kSampleSize; kMaxModels; int num_points();
//   int SolveMinimal(const std::array<int, kSampleSize>& sample, std::array<Model, kMaxModels>* models);
//   Score Evaluate(const Model& model, double bound, Sprt* sprt);  // value -1: cannot beat bound, or rejected
//   bool Refine(const Model& model, int min_consistent, Model* refined, Score* score);  // local optimisation
//   bool RecoverIfDegenerate(sample, const Model& model, Model* recovered, Score* score);  // e.g. DEGENSAC
template <typename Problem>
LoopEnd RunRobustLoop(Problem& problem, const LoopSettings& settings, const std::vector<LoopTarget>& targets,
                      const std::function<bool()>& abandon, RandomStream& random,
                      LoopState<typename Problem::Model>* state) {
  using Model = typename Problem::Model;
  constexpr int kSampleSize = Problem::kSampleSize;
  const int n = problem.num_points();
  // Samples the confidence criterion asks for, given the best model's inliers.
  auto samples_for_best_model = [&] {
    return SamplesNeeded<kSampleSize>(static_cast<double>(state->best_score.inliers) / n, settings.confidence,
                                      settings.max_iterations);
  };
  auto settled = [&] {
    if (targets.empty()) return false;
    for (const LoopTarget& target : targets) {
      const bool passed = state->have_best && state->best_score.inliers >= target.min_inliers;
      const bool failed = target.min_inliers > n || state->iterations >= target.samples_to_fail;
      if (!passed && !failed) return false;
    }
    return true;
  };
  int max_iterations = state->have_best ? samples_for_best_model() : settings.max_iterations;
  auto update_best = [&](const Model& model, const Score& score) {
    state->best = model;
    state->best_score = score;
    state->have_best = true;
    state->sprt.Update(static_cast<double>(state->best_score.inliers) / n);
    max_iterations = samples_for_best_model();
  };
  // Local optimisation of the best model, kept when it scores higher.
  auto optimize_best = [&] {
    state->local_optimization_ran = true;
    Model refined;
    Score refined_score;
    if (problem.Refine(state->best, state->best_score.inliers, &refined, &refined_score) &&
        refined_score.value > state->best_score.value) {
      update_best(refined, refined_score);
    }
  };

  std::array<int, kSampleSize> sample{};
  std::array<Model, Problem::kMaxModels> models{};
  for (; state->iterations < max_iterations; ++state->iterations) {
    const int iterations = state->iterations;
    if (settled()) return LoopEnd::kSettled;
    if (abandon && iterations % settings.abandon_poll_every == 0 && abandon()) return LoopEnd::kAbandoned;
    for (int k = 0; k < kSampleSize; ++k) {
      int index;
      do index = random.Uniform(n);
      while (std::find(sample.begin(), sample.begin() + k, index) != sample.begin() + k);
      sample[k] = index;
    }
    const int num_models = problem.SolveMinimal(sample, &models);
    const bool refine_samples = iterations >= settings.scored_without_sprt && iterations % settings.refine_every == 0;
    for (int m = 0; m < num_models; ++m) {
      Model model = models[m];
      Score score;
      if (iterations < settings.scored_without_sprt) {
        score = problem.Evaluate(model, state->best_score.value, nullptr);
      } else if (refine_samples) {
        if (problem.Evaluate(model, -1.0, &state->sprt).value < 0) continue;  // SPRT-rejected
        if (!problem.Refine(model, state->best_score.inliers, &model, &score)) continue;
      } else {
        score = problem.Evaluate(model, state->best_score.value, &state->sprt);
      }
      if (!(score.value > state->best_score.value)) continue;
      Model recovered;
      Score recovered_score;
      if (problem.RecoverIfDegenerate(sample, model, &recovered, &recovered_score)) {
        if (!(recovered_score.value > state->best_score.value)) continue;
        update_best(recovered, recovered_score);
      } else {
        update_best(model, score);
      }
      if (iterations >= settings.before_local_optimization && !refine_samples) optimize_best();
    }
    if (state->have_best && !state->local_optimization_ran && iterations >= settings.before_local_optimization) {
      optimize_best();
    }
  }
  return LoopEnd::kConfident;
}

}  // namespace vmap::internal
