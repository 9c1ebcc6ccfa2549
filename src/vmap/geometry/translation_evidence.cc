#include "vmap/geometry/translation_evidence.h"

#include <cmath>

#include <fmt/format.h>

#include "vmap/core/error.h"
#include "vmap/core/numeric.h"

namespace vmap {

void TranslationOptions::Check() const {
  const TranslationOptions defaults;  // the defaults the messages give, as declared
  if (!(max_sigma_deg > 0.0 && max_sigma_deg <= 180.0)) {
    throw OptionError("max_sigma_deg", fmt::format("{} deg is outside (0, 180]; the default is {}", max_sigma_deg,
                                                   defaults.max_sigma_deg));
  }
  if (!(min_parallax_px >= 0.0 && std::isfinite(min_parallax_px))) {
    throw OptionError("min_parallax_px",
                      fmt::format("{} px must be >= 0; the default is {}", min_parallax_px, defaults.min_parallax_px));
  }
  if (!(rival_angle_deg >= 0.0 && rival_angle_deg < 180.0)) {
    throw OptionError("rival_angle_deg", fmt::format("{} deg is outside [0, 180); the default is {}", rival_angle_deg,
                                                     defaults.rival_angle_deg));
  }
  if (!(min_rival_cost_gap >= 0.0 && std::isfinite(min_rival_cost_gap))) {
    throw OptionError("min_rival_cost_gap", fmt::format("{} must be >= 0 (0: never ambiguous); the default is {}",
                                                        min_rival_cost_gap, defaults.min_rival_cost_gap));
  }
}

void TranslationOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"max_sigma_deg", "--max-translation-sigma",
                 "Degrees: a link whose translation direction is less certain than this is marked translation "
                 "unknown (a robot gets its rotation only)"},
                max_sigma_deg);
  visitor.Visit({"min_parallax_px", "--min-translation-parallax",
                 "Pixels: a link whose verified matches moved less than this once its rotation is undone (median) "
                 "is marked translation unknown"},
                min_parallax_px);
  visitor.Visit({"rival_angle_deg", "--rival-translation-angle",
                 "Degrees: another minimum of a link's pose cost whose translation points further away than this "
                 "is a rival (see --min-rival-cost-gap)"},
                rival_angle_deg);
  visitor.Visit({"min_rival_cost_gap", "--min-rival-cost-gap",
                 "A link whose rival minimum costs less than this more than its pose (robust Sampson cost) is "
                 "marked translation unknown: its direction is ambiguous (0: never)"},
                min_rival_cost_gap);
}

bool TranslationKnown(double sigma_deg, double parallax_px, const TranslationOptions& options) {
  return TranslationKnown(sigma_deg, parallax_px, std::numeric_limits<double>::infinity(), options);
}

bool TranslationKnown(double sigma_deg, double parallax_px, double rival_cost_gap, const TranslationOptions& options) {
  return sigma_deg >= 0 && sigma_deg <= options.max_sigma_deg && parallax_px >= options.min_parallax_px &&
         rival_cost_gap >= options.min_rival_cost_gap;
}

double RotationCompensatedParallax(const NormalizedMatches& matches, const cv::Matx33d& R) {
  return Median(Displacements(matches, R));
}

TranslationEvidence AssessTranslation(const RelativePose& pose, const NormalizedMatches& pose_matches,
                                      const NormalizedMatches& verified, const PoseOptions& pose_options,
                                      const TranslationOptions& options, double rival_cost_gap) {
  TranslationEvidence evidence;
  evidence.sigma_deg = TranslationSigmaDeg(
      pose, pose_matches, pose_options.refine_inlier_factor * pose_options.threshold, pose_options.threshold);
  evidence.parallax_px = RotationCompensatedParallax(verified, pose.R);
  evidence.known = TranslationKnown(evidence.sigma_deg, evidence.parallax_px, rival_cost_gap, options);
  return evidence;
}

}  // namespace vmap
