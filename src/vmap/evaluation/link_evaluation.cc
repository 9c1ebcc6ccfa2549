#include "vmap/evaluation/link_evaluation.h"

#include <cmath>
#include <optional>
#include <vector>

#include "vmap/core/error.h"
#include "vmap/core/numeric.h"
#include "vmap/core/option_ranges.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/geometry/sampson_error.h"

namespace vmap {

void EvaluationOptions::Check() const { CheckFieldRanges(*this); }

namespace {

// Sampson errors of matches under F, on pinhole pixels (distortion removed).
std::vector<double> SampsonErrors(const cv::Matx33d& F, const std::vector<cv::Point2d>& from,
                                  const std::vector<cv::Point2d>& to) {
  std::vector<double> errors;
  for (size_t i = 0; i < from.size(); ++i) errors.push_back(SampsonDistance(F, from[i], to[i]));
  return errors;
}

}  // namespace

LinkEvaluation EvaluateLink(const VisualMap& map, int index, const GroundTruth& truth, const Camera& camera,
                            const EvaluationOptions& options) {
  const Link& link = map.links[index];
  const KeyImage& from = map.key_images[link.from_key];
  const KeyImage& to = map.key_images[link.to_key];
  LinkEvaluation e;
  e.link = index;
  e.from_frame = from.frame_index;
  e.to_frame = to.frame_index;
  e.from_source = from.source_index;
  e.to_source = to.source_index;
  e.below_tau = link.below_tau;
  e.planar = link.planar;
  e.similarity = link.similarity;
  e.num_verified = link.has_fundamental ? link.num_verified : 0;
  e.num_rejected = static_cast<int>(link.correspondences.size()) - e.num_verified;

  std::vector<cv::Point2f> verified_from, verified_to, rejected_from, rejected_to;
  for (size_t i = 0; i < link.correspondences.size(); ++i) {
    const bool verified = static_cast<int>(i) < e.num_verified;
    (verified ? verified_from : rejected_from).push_back(link.correspondences[i].p0);
    (verified ? verified_to : rejected_to).push_back(link.correspondences[i].p1);
  }

  // The pose to judge: the map's own, or the one its F gives.
  bool has_estimate = false;
  cv::Matx33d R_estimate;
  cv::Vec3d t_estimate;
  if (link.has_pose) {
    has_estimate = true;
    R_estimate = link.R;
    t_estimate = link.t;
    e.pose_source = "stored";
  } else if (link.has_fundamental && e.num_verified >= 5) {
    const RelativePose pose = PoseFromFundamental(link.F, camera, verified_from, verified_to);
    if (pose.valid) {
      has_estimate = true;
      R_estimate = pose.R;
      t_estimate = pose.t;
      e.pose_source = "fundamental";
    }
  }
  if (!has_estimate) e.pose_source = "none";
  e.translation_known = link.has_pose && link.translation_known;
  if (link.has_pose && link.translation_sigma_deg >= 0) e.translation_sigma_deg = link.translation_sigma_deg;

  const std::optional<cv::Matx44d> T_from = KeyImagePose(truth, from, options.max_time_difference);
  const std::optional<cv::Matx44d> T_to = KeyImagePose(truth, to, options.max_time_difference);
  if (!T_from || !T_to) return e;
  e.has_ground_truth = true;
  cv::Matx33d R_true;
  cv::Vec3d t_true;
  RelativeFromCameraToWorld(*T_from, *T_to, &R_true, &t_true);
  e.true_rotation_deg = RotationAngleDeg(R_true);
  e.true_baseline = cv::norm(t_true);

  if (e.true_baseline > 1e-9) {
    const cv::Matx33d F_true = FundamentalFromPose(R_true, t_true, camera.K());
    const std::vector<double> verified_errors =
        SampsonErrors(F_true, UndistortPixels(camera, verified_from), UndistortPixels(camera, verified_to));
    const std::vector<double> rejected_errors =
        SampsonErrors(F_true, UndistortPixels(camera, rejected_from), UndistortPixels(camera, rejected_to));
    e.verified_sampson_median = MedianOrNan(verified_errors);
    e.verified_within = ShareBelow(verified_errors, options.sampson_threshold_px);
    e.rejected_sampson_median = MedianOrNan(rejected_errors);
    e.rejected_within = ShareBelow(rejected_errors, options.sampson_threshold_px);
    std::vector<cv::Point2f> consistent_from, consistent_to;
    for (size_t i = 0; i < verified_errors.size(); ++i) {
      if (verified_errors[i] >= options.sampson_threshold_px) continue;
      consistent_from.push_back(verified_from[i]);
      consistent_to.push_back(verified_to[i]);
    }
    for (size_t i = 0; i < rejected_errors.size(); ++i) {
      if (rejected_errors[i] >= options.sampson_threshold_px) continue;
      consistent_from.push_back(rejected_from[i]);
      consistent_to.push_back(rejected_to[i]);
    }
    e.consistent_matches = static_cast<int>(consistent_from.size());
    if (!consistent_from.empty()) {
      e.true_parallax_px = Median(Displacements(consistent_from, consistent_to, &camera, &R_true));
    }
  } else if (!link.correspondences.empty()) {
    // No baseline: every match agrees with a pure rotation and none has parallax to speak of.
    std::vector<cv::Point2f> all_from = verified_from, all_to = verified_to;
    all_from.insert(all_from.end(), rejected_from.begin(), rejected_from.end());
    all_to.insert(all_to.end(), rejected_to.begin(), rejected_to.end());
    e.true_parallax_px = Median(Displacements(all_from, all_to, &camera, &R_true));
  }
  if (has_estimate) {
    if (e.true_baseline > 1e-9) {
      std::vector<cv::Point2f> all_from = verified_from, all_to = verified_to;
      all_from.insert(all_from.end(), rejected_from.begin(), rejected_from.end());
      all_to.insert(all_to.end(), rejected_to.begin(), rejected_to.end());
      RelativePose estimate, truth_pose;
      estimate.valid = truth_pose.valid = true;
      estimate.R = R_estimate;
      estimate.t = t_estimate;
      truth_pose.R = R_true;
      truth_pose.t = cv::normalize(t_true);
      e.true_pose_cost_excess = PoseCost(truth_pose, camera, all_from, all_to, PoseOptions()) -
                                PoseCost(estimate, camera, all_from, all_to, PoseOptions());
    }
    e.rotation_error_deg = RotationAngleDeg(R_estimate.t() * R_true);
    if (e.true_baseline > 1e-9) e.translation_error_deg = AngleBetweenDeg(t_estimate, t_true);
    const bool translation_judged = std::isfinite(e.true_parallax_px) && e.true_parallax_px >= options.min_parallax_px;
    const bool rotation_right = e.rotation_error_deg < options.max_rotation_error_deg;
    const bool translation_right =
        std::isfinite(e.translation_error_deg) && e.translation_error_deg < options.max_translation_error_deg;
    e.usable = rotation_right && (!translation_judged || translation_right);
    e.strict_usable = rotation_right && translation_right;
  }
  return e;
}

void EvaluationOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"max_rotation_error_deg", "--max-rotation-error", "Usable: rotation error below this (deg)"}
                    .Within(0, 180)
                    .ExcludingMin()
                    .Unit("deg"),
                max_rotation_error_deg);
  visitor.Visit(OptionField{"max_translation_error_deg", "--max-translation-error",
                            "Usable: translation direction error below this (deg) where the parallax is enough"}
                    .Within(0, 180)
                    .ExcludingMin()
                    .Unit("deg"),
                max_translation_error_deg);
  visitor.Visit(OptionField{"min_parallax_px", "--min-parallax",
                            "True parallax (px) from which the translation direction is judged"}
                    .AtLeast(0)
                    .Unit("px"),
                min_parallax_px);
  visitor.Visit(OptionField{"sampson_threshold_px", "--sampson-threshold",
                            "A match is on its true epipolar line within this Sampson error (px)"}
                    .AtLeast(0)
                    .ExcludingMin()
                    .Unit("px"),
                sampson_threshold_px);
  visitor.Visit(OptionField{"max_time_difference", "--max-time-difference",
                            "Seconds between a key image and its ground-truth pose (tum, euroc)"}
                    .AtLeast(0)
                    .Unit("s"),
                max_time_difference);
}

}  // namespace vmap
