#pragma once
// `vmap eval`: every link of a map checked against ground-truth camera poses (evaluation/link_evaluation.h),
// and the summary of the map. What a map is evaluated with: evaluation/evaluation_inputs.h; eval.json:
// evaluation/evaluation_json.h.

#include <string>
#include <vector>

#include "vmap/evaluation/ground_truth.h"
#include "vmap/evaluation/link_evaluation.h"
#include "vmap/geometry/camera.h"
#include "vmap/map/visual_map.h"

namespace vmap {

struct EvaluationSummary {
  int links = 0;
  int evaluated_links = 0;  // with ground truth for both key images
  int usable_links = 0;
  double usable_share = NAN;  // usable / evaluated
  int links_with_pose = 0;    // stored or from F
  double rotation_error_deg_median = NAN;
  double true_pose_cost_excess_median = NAN;  // over links with a pose and ground truth
  double translation_error_deg_median = NAN;  // over links with true parallax >= min_parallax_px
  double verified_within_mean = NAN;          // mean over links of the share of verified matches within 2 px
  double rejected_within_mean = NAN;          // the same for the rejected tentative matches
  // Every evaluated link's translation judged (LinkEvaluation::strict_usable).
  int strict_usable_links = 0;
  double strict_usable_share = NAN;
  // Evaluated links the map marks translation unknown ("flagged"), and how many of them were in fact wrong
  // (not strict_usable); the others, how many were right (strict_usable) and usable, and how many were
  // more than 90 degrees off (pointing backwards) without a flag.
  int flagged_links = 0;
  int flagged_wrong_links = 0;
  double flagged_wrong_share = NAN;
  int unflagged_links = 0;
  int unflagged_right_links = 0;
  double unflagged_right_share = NAN;
  int unflagged_usable_links = 0;
  double unflagged_usable_share = NAN;
  int unflagged_reversed_links = 0;
};

struct MapEvaluation {
  std::string map_path;
  std::string ground_truth_path;
  GroundTruthFormat ground_truth_format = GroundTruthFormat::kAuto;
  Camera camera;
  EvaluationOptions options;
  std::vector<LinkEvaluation> links;
  EvaluationSummary summary;
};

// Evaluates every link of `map` with the camera of its key images (the map's own, or one given).
MapEvaluation EvaluateMap(const VisualMap& map, const GroundTruth& truth, const Camera& camera,
                          const EvaluationOptions& options);

}  // namespace vmap
