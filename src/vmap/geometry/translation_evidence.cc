#include "vmap/geometry/translation_evidence.h"

#include <cmath>

#include "vmap/core/error.h"
#include "vmap/core/numeric.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void TranslationOptions::Check() const { CheckFieldRanges(*this); }

void TranslationOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(
      OptionField{"max_sigma_deg", "--max-translation-sigma",
                  "Degrees: a link whose translation direction is less certain than this is marked translation "
                  "unknown (a robot gets its rotation only)"}
          .Within(0, 180)
          .ExcludingMin()
          .Unit("deg"),
      max_sigma_deg);
  visitor.Visit(
      OptionField{"min_parallax_px", "--min-translation-parallax",
                  "Pixels: a link whose verified matches moved less than this once its rotation is undone (median) "
                  "is marked translation unknown"}
          .AtLeast(0)
          .Unit("px"),
      min_parallax_px);
  visitor.Visit(
      OptionField{"rival_angle_deg", "--rival-translation-angle",
                  "Degrees: another minimum of a link's pose cost whose translation points further away than this "
                  "is a rival (see --min-rival-cost-gap)"}
          .Within(0, 180)
          .ExcludingMax()
          .Unit("deg"),
      rival_angle_deg);
  visitor.Visit(
      OptionField{"min_rival_cost_gap", "--min-rival-cost-gap",
                  "A link whose rival minimum costs less than this more than its pose (robust Sampson cost) is "
                  "marked translation unknown: its direction is ambiguous (0: never)"}
          .AtLeast(0)
          .Meaning("0: never ambiguous"),
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
