#pragma once
// One link of a map checked against ground-truth camera poses (`vmap eval`): would a robot servoing from one
// key image to the next with the link's geometry go the right way? The options that judge it, and what it gives.

#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/evaluation/ground_truth.h"
#include "vmap/geometry/camera.h"
#include "vmap/map/visual_map.h"

namespace vmap {

struct EvaluationOptions {
  // A link is usable when its rotation error is below max_rotation_error_deg and, where the true parallax
  // is at least min_parallax_px (below it the translation's direction is not observable), its translation
  // direction error is below max_translation_error_deg. The true parallax is measured on the link's tentative
  // matches that agree with the ground truth (Sampson error under the true F below sampson_threshold_px), so
  // that a wrong pose cannot exempt itself through its own inliers.
  double max_rotation_error_deg = 5.0;
  double max_translation_error_deg = 20.0;
  double min_parallax_px = 10.0;
  // A match is "on its true epipolar line" when its Sampson error under the true F is below this.
  double sampson_threshold_px = 2.0;
  // Seconds: a key image takes the ground-truth pose nearest in time within this (tum, euroc).
  double max_time_difference = 0.02;

  // As eval.json records them (its "options"): every field, by its name; and `vmap eval`'s flags.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Values that cannot be computed for a link are NaN (written as null in JSON).
struct LinkEvaluation {
  int link = 0;
  int from_frame = 0, to_frame = 0;    // frame indices of the two key images
  int from_source = 0, to_source = 0;  // their indices in the input
  bool below_tau = false;
  bool planar = false;  // the link's homography test (mapping/link_analysis.h)
  double similarity = 0.0;
  int num_verified = 0;
  int num_rejected = 0;
  bool has_ground_truth = false;   // both key images have a ground-truth pose
  std::string pose_source;         // "stored" (the map's pose), "fundamental" (from F), "none"
  double true_rotation_deg = NAN;  // how much the camera turned between the key images
  double true_baseline = NAN;      // how far it moved (the ground truth's unit: metres)
  // Median displacement, after the true rotation, of the tentative matches within sampson_threshold_px of
  // their true epipolar line (`consistent_matches` of them): whether the translation can be judged.
  double true_parallax_px = NAN;
  int consistent_matches = 0;
  double rotation_error_deg = NAN;
  double translation_error_deg = NAN;    // angle between the estimated and the true direction
  double verified_sampson_median = NAN;  // pixels, under the true F
  double verified_within = NAN;          // share of verified matches within sampson_threshold_px
  double rejected_sampson_median = NAN;
  double rejected_within = NAN;
  bool usable = false;
  // Every link's translation judged, whatever its parallax: rotation and translation errors both below the
  // limits.
  bool strict_usable = false;
  // What the map itself says of the stored translation (Link::translation_known, translation_sigma_deg);
  // a pose from F, or none, is not known.
  bool translation_known = false;
  double translation_sigma_deg = NAN;
  // How much more the true pose costs on the link's own tentative matches than the judged pose (PoseCost with
  // the default PoseOptions, geometry/relative_pose.h). Large: the matches, the camera or the ground truth
  // disagree, and no better fit to the matches gets closer to the truth.
  double true_pose_cost_excess = NAN;
};

// Evaluates link `index` of `map` with the camera of its key images.
LinkEvaluation EvaluateLink(const VisualMap& map, int index, const GroundTruth& truth, const Camera& camera,
                            const EvaluationOptions& options);

}  // namespace vmap
