#include "vmap/geometry/fundamental.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/option_ranges.h"
#include "vmap/geometry/magsac.h"
#include "vmap/geometry/seeded_usac.h"

namespace vmap {

VerifierMethod ParseVerifierMethod(const std::string& name) {
  return ParseEnum(kVerifierMethodNames, name, "verifier");
}

std::string VerifierMethodName(VerifierMethod method) { return EnumToName(kVerifierMethodNames, method); }

void VerifierOptions::Check() const {
  CheckFieldRanges(*this);
  const VerifierOptions defaults;  // the defaults the messages give, as declared
  if (loop_points < 0 || (loop_points > 0 && loop_points < 16) || loop_points > 1000000) {
    throw OptionError("loop_points",
                      fmt::format("must be 0 (every match) or 16 to 1000000 (default {})", defaults.loop_points));
  }
}

namespace {

// Matches that did not move (within the inlier threshold) are those of a camera that stayed where it was: a
// frame identical to its key image, a robot standing still. Every F = [e]x explains them exactly, so their
// 7-point samples do not determine a model and the estimators fail or keep a chance one (a frame identical to
// its key image was lost by `vmap localize`). When they are the majority they are the verified matches, with
// the F of a forward motion from their centroid, which they satisfy exactly. Empty result otherwise.
FundamentalResult WithoutMotion(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                const VerifierOptions& options) {
  FundamentalResult result;
  std::vector<unsigned char> still(points0.size(), 0);
  int count = 0;
  cv::Point2d centroid(0.0, 0.0);
  for (size_t i = 0; i < points0.size(); ++i) {
    const cv::Point2f d = points1[i] - points0[i];
    if (d.x * d.x + d.y * d.y <= options.threshold * options.threshold) {
      still[i] = 1;
      ++count;
      centroid += cv::Point2d(points0[i]);
    }
  }
  if (count < options.min_matches || 2 * count <= static_cast<int>(points0.size())) return result;
  centroid *= 1.0 / count;
  result.F = cv::Matx33d(0.0, -1.0, centroid.y, 1.0, 0.0, -centroid.x, -centroid.y, centroid.x, 0.0);  // [e]x
  result.F *= 1.0 / cv::norm(result.F);
  result.inlier_mask = std::move(still);
  result.num_inliers = count;
  result.success = true;
  return result;
}

FundamentalResult EstimateFromSamples(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                      const VerifierOptions& options, const EarlyStop& early_stop,
                                      const std::vector<float>* scores) {
  FundamentalResult result;
  CV_Assert(points0.size() == points1.size());
  if (static_cast<int>(points0.size()) < options.min_matches) return result;
  if (options.method == VerifierMethod::kMagsac && options.loop_points > 0 && scores &&
      scores->size() == points0.size() && early_stop.min_inliers.empty() && !early_stop.resume_from) {
    // Bounded: "not enough inliers" is accepted after max_samples_to_reject samples, as when stopping early.
    VerifierOptions bounded = options;
    bounded.max_iterations = std::min(options.max_iterations, options.max_samples_to_reject);
    return EstimateFundamentalMagsacOnBest(points0, points1, *scores, bounded);
  }
  if (options.method == VerifierMethod::kMagsac && options.own_magsac) {
    return EstimateFundamentalMagsac(points0, points1, options, early_stop);
  }
  cv::Mat F;
  std::vector<unsigned char> mask;
  if (options.method == VerifierMethod::kRansac) {
    // FM_RANSAC draws from a fixed-seed generator inside OpenCV: repeatable.
    F = cv::findFundamentalMat(points0, points1, cv::FM_RANSAC, options.threshold, options.confidence,
                               options.max_iterations, mask);
  } else {
    // The presets of OpenCV 4.6's flag-based call (usac::setParameters), with the seed made explicit.
    cv::UsacParams params =
        SeededUsacParams(options.confidence, options.max_iterations, options.threshold, options.seed);
    switch (options.method) {
      case VerifierMethod::kMagsac:
        params.score = cv::SCORE_METHOD_MAGSAC;
        params.loMethod = cv::LOCAL_OPTIM_SIGMA;
        params.loSampleSize = 50;
        params.loIterations = 10;
        break;
      case VerifierMethod::kAccurate:
        params.score = cv::SCORE_METHOD_MSAC;
        params.loMethod = cv::LOCAL_OPTIM_GC;
        params.loSampleSize = 20;
        params.loIterations = 25;
        break;
      default:  // USAC_DEFAULT
        params.score = cv::SCORE_METHOD_MSAC;
        params.loMethod = cv::LOCAL_OPTIM_INNER_AND_ITER_LO;
        params.loSampleSize = 21;  // the fundamental-matrix default of the preset
        params.loIterations = 15;
        break;
    }
    F = cv::findFundamentalMat(points0, points1, mask, params);
  }
  // OpenCV may return several stacked 3x3 solutions (7-point); the first is the chosen one.
  if (F.empty() || F.rows < 3 || F.cols != 3 || mask.size() != points0.size()) return result;
  result.inlier_mask = std::move(mask);
  for (unsigned char m : result.inlier_mask) result.num_inliers += m ? 1 : 0;
  if (result.num_inliers < options.min_matches) {
    result.inlier_mask.clear();
    result.num_inliers = 0;
    return result;
  }
  F.rowRange(0, 3).convertTo(cv::Mat(3, 3, CV_64F, result.F.val), CV_64F);
  result.success = true;
  return result;
}

}  // namespace

FundamentalResult EstimateFundamental(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                      const VerifierOptions& options, const EarlyStop& early_stop,
                                      const std::vector<float>* scores) {
  FundamentalResult estimated = EstimateFromSamples(points0, points1, options, early_stop, scores);
  if (estimated.abandoned) return estimated;
  // A camera that moved gives a model that also explains its still matches (those near the epipole, or far
  // away): the estimator's answer stands unless it explains fewer matches than stayed put.
  FundamentalResult still = WithoutMotion(points0, points1, options);
  if (still.success && (!estimated.success || estimated.num_inliers < still.num_inliers)) return still;
  return estimated;
}

void VerifierOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Verifier: the fundamental matrix");
  visitor.Visit(OptionField{"method", "--verifier", "Fundamental matrix estimator: "}.ListingNames(),
                EnumField(method, kVerifierMethodNames, ParseVerifierMethod));
  visitor.Visit(
      OptionField{"threshold", "--threshold", "Verifier inlier threshold in pixels"}.Within(0, 100).ExcludingMin().Unit(
          "px"),
      threshold);
  visitor.Visit(
      OptionField{"confidence", "--confidence", "Verifier confidence"}.Within(0, 1).ExcludingMin().ExcludingMax(),
      confidence);
  visitor.Visit(OptionField{"max_iterations", "--max-iters", "Verifier maximum iterations"}.Within(1, 10000000),
                max_iterations);
  visitor.Visit(OptionField{"seed", "--seed", "Verifier random seed (same seed, same map)"}.AtLeast(0), seed);
  visitor.Visit(OptionField{"min_matches"}.AtLeast(8).Meaning("the 8-point algorithm needs 8 matches"), min_matches);
  visitor.Visit(
      OptionField{"max_samples_to_reject", "--max-samples-to-reject",
                  "Samples after which S < tau is settled when decisions stop early (--max-iters or more: the "
                  "confidence criterion alone; ignored with --exhaustive)"}
          .Within(1, 10000000)
          .Meaning("max_iterations or more keeps the confidence criterion"),
      max_samples_to_reject);
}

}  // namespace vmap
