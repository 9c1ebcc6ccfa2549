#pragma once
// `vmap eval`: every link of a map checked against ground-truth camera poses. Would a robot servoing from
// one key image to the next with the link's geometry go the right way?

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

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

// The camera to evaluate a map with: the map's own, else `camera_option`, else the one that comes with the
// map's input, scaled to the map's frame size. Throws OptionError ("camera") when there is none.
Camera EvaluationCamera(const VisualMap& map, const std::string& camera_option);
// The camera `camera_option` gives (nullopt when it is empty), checked: an OptionError for "camera" when it is
// neither a calibration file nor fx,fy,cx,cy[,...] of finite, positive focal lengths. EvaluationCamera calls it;
// a command calls it first, so that a wrong value is refused before anything else is read.
std::optional<Camera> ParseEvaluationCamera(const std::string& camera_option);

// The ground truth of a map: the file given (format from `format`, or detected), else the one that comes
// with the map's input. Throws OptionError ("gt.path" when there is none, "gt.format" when it cannot be told).
GroundTruth MapGroundTruth(const VisualMap& map, const std::string& gt_path, GroundTruthFormat format);

inline constexpr const char* kEvaluationFileName = "eval.json";

// JSON document ("format": "vmap-eval") with the options, one object per link and the summary.
std::string EvaluationToJson(const MapEvaluation& evaluation);
// Reads eval.json back (for the report). Throws InputError naming the file when it is malformed.
MapEvaluation ReadEvaluation(const std::string& path);

}  // namespace vmap
