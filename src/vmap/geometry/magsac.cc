#include "vmap/geometry/magsac.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "vmap/geometry/degensac.h"
#include "vmap/geometry/fundamental_solvers.h"
#include "vmap/geometry/magsac_scoring.h"
#include "vmap/geometry/robust_loop.h"

namespace vmap {

// Where a loop stopped early (its state) and what the run was given, so that a run resumed from it can be
// checked to be the same run.
struct MagsacCheckpoint {
  int num_points = 0;
  std::uint64_t points_fingerprint = 0;
  double threshold = 0, confidence = 0;
  int max_iterations = 0, seed = 0;

  std::uint64_t random_draws = 0;
  internal::LoopState<internal::Model> loop;
};

namespace {

using internal::LoopEnd;
using internal::LoopState;
using internal::LoopTarget;
using internal::MagsacScorer;
using internal::Model;
using internal::NormalizedPoints;
using internal::RandomStream;
using internal::Score;
using internal::SevenPointModels;
using internal::SevenPointSample;
using internal::Sprt;

constexpr int kPolishRounds = 3;

// The fundamental matrix as the robust loop's Problem: 7-point models, the MAGSAC++ score, sigma-consensus++ as
// the local optimisation, DEGENSAC for samples mostly on one plane.
class FundamentalProblem {
 public:
  using Model = internal::Model;
  static constexpr int kSampleSize = internal::kSevenPointSampleSize;
  static constexpr int kMaxModels = internal::kSevenPointMaxModels;

  FundamentalProblem(const NormalizedPoints& points, MagsacScorer& scorer, RandomStream& random)
      : points_(points), scorer_(scorer), random_(random) {}

  int num_points() const { return static_cast<int>(points_.pixels.size()); }
  int SolveMinimal(const SevenPointSample& sample, SevenPointModels* models) {
    return internal::SolveSevenPoint(points_, sample, models, &stationary_sample_);
  }
  Score Evaluate(const Model& model, double bound, Sprt* sprt) { return scorer_.Evaluate(model, bound, sprt); }
  bool Refine(const Model& model, int min_consistent, Model* refined, Score* score) {
    return scorer_.SigmaConsensus(model, min_consistent, random_, refined, score);
  }
  // A stationary sample's model is the degenerate case itself (H = I explains every point): no plane and
  // parallax to recover it from.
  bool RecoverIfDegenerate(const SevenPointSample& sample, const Model& model, Model* recovered, Score* score) {
    return !stationary_sample_ &&
           internal::RecoverIfDegenerate(points_, sample, model, scorer_, random_, recovered, score);
  }

 private:
  const NormalizedPoints& points_;
  MagsacScorer& scorer_;
  RandomStream& random_;
  bool stationary_sample_ = false;  // the last sample's points had not moved
};

// The points in a random order, so that SPRT sees a fair sample of them first. The order is drawn from the
// points sorted by coordinates, so that the result does not depend on the order they come in: a link verified
// again from its stored correspondences (verified ones first) continues exactly the run that decided it.
NormalizedPoints InVisitingOrder(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                 RandomStream& random, std::vector<int>* order) {
  const int n = static_cast<int>(points0.size());
  order->resize(n);
  for (int i = 0; i < n; ++i) (*order)[i] = i;
  std::sort(order->begin(), order->end(), [&](int a, int b) {
    const cv::Point2f &a0 = points0[a], &b0 = points0[b], &a1 = points1[a], &b1 = points1[b];
    return std::tie(a0.x, a0.y, a1.x, a1.y) < std::tie(b0.x, b0.y, b1.x, b1.y);
  });
  for (int i = n - 1; i > 0; --i) std::swap((*order)[i], (*order)[random.Uniform(i + 1)]);
  NormalizedPoints points;
  points.pixels.resize(n);
  for (int i = 0; i < n; ++i) {
    const int k = (*order)[i];
    points.pixels[i] = {points0[k].x, points0[k].y, points1[k].x, points1[k].y};
  }
  return points;
}

// One robust estimation.
class Estimator {
 public:
  Estimator(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
            const VerifierOptions& options, const EarlyStop& early_stop)
      : options_(options),
        random_(static_cast<std::uint32_t>(options.seed)),
        n_(static_cast<int>(points0.size())),
        points_(InVisitingOrder(points0, points1, random_, &order_)),
        scorer_(points_, options.threshold, &state_.statistics),
        abandon_(early_stop.abandon),
        resume_from_(early_stop.resume_from) {
    for (int target : early_stop.min_inliers) {
      const int needed = SamplesToSettle(static_cast<double>(target) / n_, options.confidence, options.max_iterations);
      targets_.push_back({target, std::min(needed, options.max_samples_to_reject)});
    }
  }

  FundamentalResult Run(MagsacStatistics* statistics);
  // No sample loop: `model` (from a loop over some of these points) refined by sigma-consensus++ and polished on
  // all of them, and its inliers among them.
  FundamentalResult RefineFrom(const Model& model, MagsacStatistics* statistics);

 private:
  // Steps shared by Run and RefineFrom once the best model is known: polished, then its inliers, into `result`.
  FundamentalResult PolishAndCount(FundamentalResult result, MagsacStatistics* statistics);
  // FNV-1a over the points in visiting order: a resumed run must be given the points its checkpoint was.
  std::uint64_t PointsFingerprint() const;
  std::shared_ptr<const MagsacCheckpoint> Checkpoint() const;
  void Resume(const MagsacCheckpoint& checkpoint);
  void PolishBest();
  bool PassesAllSettledTargets(int inliers) const;

  const VerifierOptions& options_;
  RandomStream random_;
  const int n_;
  std::vector<int> order_;   // visiting order -> index in the points given
  NormalizedPoints points_;  // in visiting order
  LoopState<Model> state_;
  MagsacScorer scorer_;
  std::vector<LoopTarget> targets_;
  std::function<bool()> abandon_;
  std::shared_ptr<const MagsacCheckpoint> resume_from_;
};

std::uint64_t Estimator::PointsFingerprint() const {
  std::uint64_t hash = 14695981039346656037ull;
  for (const internal::Point& p : points_.pixels) {
    for (double v : {p.x0, p.y0, p.x1, p.y1}) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      hash = (hash ^ bits) * 1099511628211ull;
    }
  }
  return hash;
}

std::shared_ptr<const MagsacCheckpoint> Estimator::Checkpoint() const {
  auto checkpoint = std::make_shared<MagsacCheckpoint>();
  checkpoint->num_points = n_;
  checkpoint->points_fingerprint = PointsFingerprint();
  checkpoint->threshold = options_.threshold;
  checkpoint->confidence = options_.confidence;
  checkpoint->max_iterations = options_.max_iterations;
  checkpoint->seed = options_.seed;
  checkpoint->random_draws = random_.draws();
  checkpoint->loop = state_;
  return checkpoint;
}

void Estimator::Resume(const MagsacCheckpoint& checkpoint) {
  if (checkpoint.num_points != n_ || checkpoint.points_fingerprint != PointsFingerprint() ||
      checkpoint.threshold != options_.threshold || checkpoint.confidence != options_.confidence ||
      checkpoint.max_iterations != options_.max_iterations || checkpoint.seed != options_.seed ||
      checkpoint.random_draws < random_.draws()) {
    throw std::logic_error("EstimateFundamentalMagsac: resumed with other points or options than its checkpoint's");
  }
  random_.SkipTo(checkpoint.random_draws);
  state_ = checkpoint.loop;
  state_.statistics.stopped_early = false;
}

bool Estimator::PassesAllSettledTargets(int inliers) const {
  for (const LoopTarget& target : targets_) {
    if (state_.best_score.inliers >= target.min_inliers && inliers < target.min_inliers) return false;
  }
  return true;
}

// Least squares on the inliers, kept while the score does not get worse; a decision settled as passed stays
// passed.
void Estimator::PolishBest() {
  std::vector<int> inliers(n_);
  Model current = state_.best;
  for (int round = 0; round < kPolishRounds; ++round) {
    int count = 0;
    for (int i = 0; i < n_; ++i) {
      if (scorer_.IsInlier(current, i)) inliers[count++] = i;
    }
    Model fitted;
    if (!internal::FitFundamental(points_, inliers, count, nullptr, &fitted)) break;
    const Score score = scorer_.FullScore(fitted);
    if (score.value < state_.best_score.value || !PassesAllSettledTargets(score.inliers)) break;
    const bool small_change = std::abs(score.inliers - state_.best_score.inliers) < 0.05 * state_.best_score.inliers;
    state_.best = fitted;
    state_.best_score = score;
    current = fitted;
    if (small_change) break;
  }
}

FundamentalResult Estimator::Run(MagsacStatistics* statistics) {
  FundamentalResult result;
  // 1. Enough points for a sample and for a result, not all at one place in either image.
  if (n_ < std::max(internal::kSevenPointSampleSize, options_.min_matches) || !points_.Normalize()) return result;

  // 2. A run stopped early goes on from where it stopped.
  if (resume_from_) Resume(*resume_from_);

  // 3. The robust loop, until the confidence criterion, every decision settled, or abandoned.
  internal::LoopSettings settings;
  settings.confidence = options_.confidence;
  settings.max_iterations = options_.max_iterations;
  FundamentalProblem problem(points_, scorer_, random_);
  const LoopEnd end = internal::RunRobustLoop(problem, settings, targets_, abandon_, random_, &state_);
  state_.statistics.iterations = state_.iterations;
  if (end == LoopEnd::kAbandoned) {
    if (statistics) *statistics = state_.statistics;
    result.abandoned = true;
    return result;
  }

  // 4. Stopped early: where, so that the run can go on.
  state_.statistics.stopped_early = end == LoopEnd::kSettled;
  if (end == LoopEnd::kSettled) result.checkpoint = Checkpoint();
  if (!state_.have_best) {
    if (statistics) *statistics = state_.statistics;
    return result;
  }

  // 5-6. The best model polished by least squares on its inliers, and its inliers.
  return PolishAndCount(std::move(result), statistics);
}

FundamentalResult Estimator::RefineFrom(const Model& model, MagsacStatistics* statistics) {
  if (n_ < std::max(internal::kSevenPointSampleSize, options_.min_matches) || !points_.Normalize()) return {};
  state_.best = model;
  state_.best_score = scorer_.FullScore(model);
  state_.have_best = true;
  Model refined;
  Score refined_score;
  if (scorer_.SigmaConsensus(model, 0, random_, &refined, &refined_score) &&
      refined_score.value > state_.best_score.value) {
    state_.best = refined;
    state_.best_score = refined_score;
  }
  return PolishAndCount({}, statistics);
}

FundamentalResult Estimator::PolishAndCount(FundamentalResult result, MagsacStatistics* statistics) {
  PolishBest();
  // Its inliers, in the order the points were given.
  result.inlier_mask.assign(n_, 0);
  for (int i = 0; i < n_; ++i) {
    if (scorer_.IsInlier(state_.best, i)) {
      result.inlier_mask[order_[i]] = 1;
      ++result.num_inliers;
    }
  }
  if (statistics) *statistics = state_.statistics;
  if (result.num_inliers < options_.min_matches) {
    result.inlier_mask.clear();
    result.num_inliers = 0;
    return result;
  }
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) result.F(r, c) = state_.best[3 * r + c];
  result.success = true;
  return result;
}

}  // namespace

int SamplesToSettle(double inlier_ratio, double confidence, int max_iterations) {
  return internal::SamplesNeeded<internal::kSevenPointSampleSize>(inlier_ratio, confidence, max_iterations);
}

FundamentalResult EstimateFundamentalMagsac(const std::vector<cv::Point2f>& points0,
                                            const std::vector<cv::Point2f>& points1, const VerifierOptions& options,
                                            const EarlyStop& early_stop, MagsacStatistics* statistics) {
  CV_Assert(points0.size() == points1.size());
  Estimator estimator(points0, points1, options, early_stop);
  return estimator.Run(statistics);
}

FundamentalResult EstimateFundamentalMagsacOnBest(const std::vector<cv::Point2f>& points0,
                                                  const std::vector<cv::Point2f>& points1,
                                                  const std::vector<float>& scores, const VerifierOptions& options,
                                                  MagsacStatistics* statistics) {
  CV_Assert(points0.size() == points1.size());
  const int n = static_cast<int>(points0.size());
  if (options.loop_points <= 0 || n <= options.loop_points || static_cast<int>(scores.size()) != n) {
    return EstimateFundamentalMagsac(points0, points1, options, {}, statistics);
  }
  // Best score first; ties by coordinates, so that the subset does not depend on the order the matches come in.
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (scores[a] != scores[b]) return scores[a] > scores[b];
    return std::tie(points0[a].x, points0[a].y, points1[a].x, points1[a].y) <
           std::tie(points0[b].x, points0[b].y, points1[b].x, points1[b].y);
  });
  std::vector<cv::Point2f> best0(options.loop_points), best1(options.loop_points);
  for (int i = 0; i < options.loop_points; ++i) {
    best0[i] = points0[order[i]];
    best1[i] = points1[order[i]];
  }
  MagsacStatistics loop_statistics;
  const FundamentalResult loop = EstimateFundamentalMagsac(best0, best1, options, {}, &loop_statistics);
  if (statistics) *statistics = loop_statistics;
  if (!loop.success) return {};
  Model model;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) model[3 * r + c] = loop.F(r, c);
  Estimator all(points0, points1, options, {});
  MagsacStatistics refine_statistics;
  FundamentalResult result = all.RefineFrom(model, &refine_statistics);
  if (statistics) {
    statistics->models_scored += refine_statistics.models_scored;
    statistics->local_optimizations += refine_statistics.local_optimizations;
  }
  return result;
}

}  // namespace vmap
