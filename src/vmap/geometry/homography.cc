#include "vmap/geometry/homography.h"

#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/option_ranges.h"
#include "vmap/geometry/seeded_usac.h"

namespace vmap {

void HomographyOptions::Check() const {
  CheckFieldRanges(*this);
  if (!(confidence > 0.0 && confidence < 1.0)) throw OptionError("confidence", "must be in (0, 1)");
  if (max_iterations < 1) throw OptionError("max_iterations", "must be >= 1");
}

HomographyCheck CheckHomography(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                                const HomographyOptions& options) {
  CV_Assert(from.size() == to.size());
  HomographyCheck check;
  if (from.size() < 4) return check;
  cv::UsacParams params = SeededUsacParams(options.confidence, options.max_iterations, options.threshold, options.seed);
  params.score = cv::SCORE_METHOD_MSAC;
  params.loMethod = cv::LOCAL_OPTIM_INNER_AND_ITER_LO;
  params.loSampleSize = 14;
  params.loIterations = 15;
  cv::Mat H, mask;
  try {
    H = cv::findHomography(from, to, mask, params);
  } catch (const cv::Exception&) {
    return check;
  }
  if (H.empty()) return check;
  H.convertTo(H, CV_64F);
  check.H = cv::Matx33d(H);
  check.estimated = true;
  // Counted here with one plain definition (forward transfer error), whatever the estimator's own scoring.
  const double threshold2 = options.threshold * options.threshold;
  for (size_t i = 0; i < from.size(); ++i) {
    const cv::Vec3d x = check.H * cv::Vec3d(from[i].x, from[i].y, 1.0);
    if (!(std::abs(x[2]) > 1e-12)) continue;
    const double dx = x[0] / x[2] - to[i].x, dy = x[1] / x[2] - to[i].y;
    if (dx * dx + dy * dy <= threshold2) ++check.num_explained;
  }
  check.share = static_cast<double>(check.num_explained) / from.size();
  check.explains = check.share >= options.min_share;
  return check;
}

void HomographyOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"threshold"}.AtLeast(0).ExcludingMin().Unit("px"), threshold);
  visitor.Visit(OptionField{"min_share"}.Within(0, 1).ExcludingMin(), min_share);
}

}  // namespace vmap
