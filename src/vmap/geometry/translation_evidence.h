#pragma once
// Whether a pose's translation direction can be trusted: the one place that decides the flags of a pose, a
// map's link (map.json's links[].translation_sigma_deg, parallax, translation_known; mapping/link_analysis.cc)
// as a localization comparison (localization/localizer.cc).

#include <limits>

#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/geometry/pose_refinement.h"
#include "vmap/geometry/relative_pose.h"

namespace vmap {

// When a translation direction is trusted (map.json's links[].translation_known, localization results): both
// its sigma is small and the matches moved enough once the rotation is undone. The sigma alone trusts some
// pairs a few centimetres apart whose errors are not the pixel noise it assumes (calibration, rolling
// shutter); the parallax alone distrusts forward motion, whose median parallax is small where t is well
// known. Both chosen on kitti07 and redkitchen 0-499 (docs/link-poses.md).
struct TranslationOptions {
  double max_sigma_deg = 3.0;    // largest TranslationSigmaDeg of a trusted direction
  double min_parallax_px = 3.0;  // smallest median rotation-compensated displacement (Displacements) of one
  // A rival minimum (RivalCostGap) whose translation is more than rival_angle_deg away and that costs less
  // than min_rival_cost_gap more than the chosen pose makes the direction ambiguous. The gap is in PoseCost
  // units (about half the sum of squared Sampson errors in pixels for errors under the 1 px loss scale).
  // Chosen on kitti07 and redkitchen 0-499 (docs/link-poses.md).
  double rival_angle_deg = 15.0;
  double min_rival_cost_gap = 8.0;

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};
// Without a rival (a single start, localization's refined pose of F): rival_cost_gap is infinity.
bool TranslationKnown(double sigma_deg, double parallax_px, const TranslationOptions& options);
bool TranslationKnown(double sigma_deg, double parallax_px, double rival_cost_gap, const TranslationOptions& options);

// The median displacement of the matches, in pixels, once the rotation R is undone (Displacements): what
// triangulation and the translation's direction rest on. A link's and a comparison's "parallax".
double RotationCompensatedParallax(const NormalizedMatches& matches, const cv::Matx33d& R);

// A pose's flags.
struct TranslationEvidence {
  double sigma_deg = -1.0;    // TranslationSigmaDeg
  double parallax_px = -1.0;  // RotationCompensatedParallax of the verified matches
  bool known = false;         // TranslationKnown
};

// The flags of a valid `pose`: its sigma on `pose_matches` (the matches it was estimated on, within
// pose_options' inlier threshold, refine_inlier_factor * threshold, with its Cauchy scale, threshold), its
// parallax on `verified` (F's inliers), and whether both, and `rival_cost_gap` (RivalCostGap of its minima;
// infinity without a rival), let the direction be trusted.
TranslationEvidence AssessTranslation(const RelativePose& pose, const NormalizedMatches& pose_matches,
                                      const NormalizedMatches& verified, const PoseOptions& pose_options,
                                      const TranslationOptions& options,
                                      double rival_cost_gap = std::numeric_limits<double>::infinity());

}  // namespace vmap
