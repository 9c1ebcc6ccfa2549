#include "vmap/evaluation/map_evaluation.h"

#include <cmath>

#include "vmap/core/numeric.h"

namespace vmap {

MapEvaluation EvaluateMap(const VisualMap& map, const GroundTruth& truth, const Camera& camera,
                          const EvaluationOptions& options) {
  options.Check();
  MapEvaluation evaluation;
  evaluation.ground_truth_path = truth.path;
  evaluation.ground_truth_format = truth.format;
  evaluation.camera = camera;
  evaluation.options = options;
  std::vector<double> rotation_errors, translation_errors, verified_within, rejected_within, cost_excesses;
  EvaluationSummary& s = evaluation.summary;
  for (int i = 0; i < static_cast<int>(map.links.size()); ++i) {
    LinkEvaluation e = EvaluateLink(map, i, truth, camera, options);
    ++s.links;
    if (e.pose_source != "none") ++s.links_with_pose;
    if (e.has_ground_truth) {
      ++s.evaluated_links;
      s.usable_links += e.usable ? 1 : 0;
      rotation_errors.push_back(e.rotation_error_deg);
      cost_excesses.push_back(e.true_pose_cost_excess);
      if (std::isfinite(e.true_parallax_px) && e.true_parallax_px >= options.min_parallax_px) {
        translation_errors.push_back(e.translation_error_deg);
      }
      verified_within.push_back(e.verified_within);
      rejected_within.push_back(e.rejected_within);
      s.strict_usable_links += e.strict_usable ? 1 : 0;
      if (e.translation_known) {
        ++s.unflagged_links;
        s.unflagged_right_links += e.strict_usable ? 1 : 0;
        s.unflagged_usable_links += e.usable ? 1 : 0;
        s.unflagged_reversed_links += std::isfinite(e.translation_error_deg) && e.translation_error_deg > 90 ? 1 : 0;
      } else {
        ++s.flagged_links;
        s.flagged_wrong_links += e.strict_usable ? 0 : 1;
      }
    }
    evaluation.links.push_back(std::move(e));
  }
  const auto share = [](int part, int whole) { return whole > 0 ? static_cast<double>(part) / whole : NAN; };
  s.usable_share = share(s.usable_links, s.evaluated_links);
  s.strict_usable_share = share(s.strict_usable_links, s.evaluated_links);
  s.flagged_wrong_share = share(s.flagged_wrong_links, s.flagged_links);
  s.unflagged_right_share = share(s.unflagged_right_links, s.unflagged_links);
  s.unflagged_usable_share = share(s.unflagged_usable_links, s.unflagged_links);
  s.rotation_error_deg_median = MedianOfFinite(rotation_errors);
  s.translation_error_deg_median = MedianOfFinite(translation_errors);
  s.true_pose_cost_excess_median = MedianOfFinite(cost_excesses);
  s.verified_within_mean = MeanOfFinite(verified_within);
  s.rejected_within_mean = MeanOfFinite(rejected_within);
  return evaluation;
}

}  // namespace vmap
