#pragma once
// The MAGSAC++ score of a fundamental matrix (Barath et al., CVPR 2020; 4 degrees of freedom, sigma_max =
// 2.5 px / 3.64) over its squared Sampson errors, and sigma-consensus++, the local optimisation that refits a
// model with MAGSAC++ weights: the scoring half of vmap's MAGSAC++ (magsac.cc). Internal to geometry/.

#include <vector>

#include "vmap/geometry/fundamental_solvers.h"
#include "vmap/geometry/magsac.h"
#include "vmap/geometry/robust_loop.h"
#include "vmap/geometry/sampson_error.h"

namespace vmap::internal {

class MagsacTables;

// Scores models over `points` (pixels, in visiting order; they must outlive the scorer); counts the models
// scored and the local optimisations into `statistics`.
class MagsacScorer {
 public:
  MagsacScorer(const NormalizedPoints& points, double threshold, MagsacStatistics* statistics);

  // The MAGSAC++ score of a model over the points in visiting order. Stops (and returns value -1) as soon as the
  // model can no longer beat `bound`, or when SPRT rejects it.
  // With `sprt` (and SPRT active) the model is tested point by point and rejected early.
  Score Evaluate(const Model& model, double bound, Sprt* sprt);
  // The score over every point.
  Score FullScore(const Model& model) { return Evaluate(model, -1.0, nullptr); }

  // sigma-consensus++: iteratively re-weighted least squares with MAGSAC++ weights on the points within the
  // maximum threshold (a random 50 of them per round, as OpenCV does), keeping the best-scoring model of the
  // rounds. Each pass over the points both scores the current model and weighs the points for the next fit.
  // False (no refit) when fewer than `min_consistent` points are within the maximum threshold: the model cannot
  // beat the best one's inliers.
  bool SigmaConsensus(const Model& model, int min_consistent, RandomStream& random, Model* refined, Score* score);

  // Whether point i is an inlier of `model` (Sampson distance below the threshold).
  bool IsInlier(const Model& model, int i) const {
    return SquaredSampson(model, points_.pixels[i]) < threshold_squared_;
  }

 private:
  const NormalizedPoints& points_;
  const MagsacTables& tables_;
  MagsacStatistics* statistics_;
  const int n_;
  double max_squared_ = 0, inv_max_squared_ = 0, threshold_squared_ = 0;
  PointColumns columns_;                // the points, column by column
  std::vector<double> squared_errors_;  // scratch for SquaredSampsonErrors
  std::vector<int> scratch_indices_;
  std::vector<double> scratch_weights_;
};

}  // namespace vmap::internal
