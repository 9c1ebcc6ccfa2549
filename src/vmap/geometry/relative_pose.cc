#include "vmap/geometry/relative_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/option_ranges.h"
#include "vmap/geometry/pose_refinement.h"
#include "vmap/geometry/seeded_usac.h"

namespace vmap {

PoseMethod ParsePoseMethod(const std::string& name) { return ParseEnum(kPoseMethodNames, name, "pose method"); }

std::string PoseMethodName(PoseMethod method) { return EnumToName(kPoseMethodNames, method); }

void PoseOptions::Check() const {
  CheckFieldRanges(*this);
  const PoseOptions defaults;  // the defaults the messages give, as declared
  if (!(refine_inlier_factor >= 1.0)) throw OptionError("refine_inlier_factor", "must be >= 1");
  if (starts < 0 || starts > 100)
    throw OptionError("starts", fmt::format("must be in [0, 100] (default {})", defaults.starts));
  if (min_matches < 5) throw OptionError("min_matches", "must be >= 5: the five-point solver needs 5 matches");
}

namespace {

// Matches (flagged in `mask`, all when empty) whose two rays meet in front of both cameras under (R, t):
// the depths z_from, z_to of the least-squares solution of z_to y_to = z_from R y_from + t are both positive.
// Rays too close to parallel to place the point (a point at infinity) do not vote.
int CountInFront(const cv::Matx33d& R, const cv::Vec3d& t, const std::vector<cv::Point2d>& from,
                 const std::vector<cv::Point2d>& to, const std::vector<unsigned char>& mask) {
  int count = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    if (!mask.empty() && !mask[i]) continue;
    const cv::Vec3d a = R * cv::Vec3d(from[i].x, from[i].y, 1.0), b(to[i].x, to[i].y, 1.0);
    const double aa = a.dot(a), bb = b.dot(b), ab = a.dot(b), at = a.dot(t), bt = b.dot(t);
    const double det = aa * bb - ab * ab;
    if (!(det > 1e-12 * aa * bb)) continue;
    const double z_from = (ab * bt - at * bb) / det;
    const double z_to = (aa * bt - ab * at) / det;
    count += z_from > 0 && z_to > 0 ? 1 : 0;
  }
  return count;
}

// Decomposes E with the cheirality test on the matches flagged in `mask` (all when empty): of the four
// poses E allows, the one that puts most of them in front of both cameras. (Hand-written rather than
// cv::recoverPose: that one drops every point farther than 50 baselines, i.e. every point of a short
// baseline such as a hand-held camera moving 1 cm in front of a table 1.5 m away, and triangulates each
// point by SVD four times, far slower: docs/measurements/code-choices.md, "Decomposing E by hand".)
RelativePose Decompose(const cv::Mat& E, const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to,
                       const std::vector<unsigned char>& mask) {
  RelativePose pose;
  if (E.empty() || from.size() < 5) return pose;
  cv::Mat R1, R2, t;
  cv::decomposeEssentialMat(E, R1, R2, t);
  const cv::Vec3d direction(t.at<double>(0), t.at<double>(1), t.at<double>(2));
  int best = 0;
  for (const cv::Mat& R : {R1, R2}) {
    for (const double sign : {1.0, -1.0}) {
      const cv::Matx33d rotation(R);
      const int in_front = CountInFront(rotation, sign * direction, from, to, mask);
      if (in_front > best) {  // ties keep the earlier candidate: deterministic
        best = in_front;
        pose.R = rotation;
        pose.t = sign * direction;
      }
    }
  }
  const double norm = cv::norm(pose.t);
  if (best == 0 || !(norm > 0)) return RelativePose();
  pose.t /= norm;
  pose.num_inliers = best;
  pose.valid = true;
  return pose;
}

}  // namespace

NormalizedMatches::NormalizedMatches(const Camera& camera, const std::vector<cv::Point2f>& from_pixels,
                                     const std::vector<cv::Point2f>& to_pixels)
    : from(NormalizePoints(camera, from_pixels)),
      to(NormalizePoints(camera, to_pixels)),
      fx(camera.fx),
      fy(camera.fy),
      K(camera.K()) {
  CV_Assert(from_pixels.size() == to_pixels.size());
}

NormalizedMatches NormalizedMatches::Select(const std::vector<unsigned char>& mask) const {
  NormalizedMatches selected = *this;
  selected.from.clear();
  selected.to.clear();
  for (size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    selected.from.push_back(from[i]);
    selected.to.push_back(to[i]);
  }
  return selected;
}

RelativePose EnforceCheirality(const RelativePose& pose, const NormalizedMatches& matches, double inlier_threshold) {
  if (!pose.valid) return pose;
  const std::vector<unsigned char> mask = MatchesWithin(pose, matches, inlier_threshold);
  const int given = CountInFront(pose.R, pose.t, matches.from, matches.to, mask);
  const RelativePose decided = Decompose(cv::Mat(CrossMatrix(pose.t) * pose.R), matches.from, matches.to, mask);
  if (!decided.valid || decided.num_inliers <= given) return pose;
  RelativePose result = pose;
  result.R = decided.R;
  result.t = decided.t;
  return result;
}

RelativePose EnforceCheirality(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                               const std::vector<cv::Point2f>& to, double inlier_threshold) {
  if (!pose.valid) return pose;
  return EnforceCheirality(pose, NormalizedMatches(camera, from, to), inlier_threshold);
}

double PoseCost(const RelativePose& pose, const NormalizedMatches& matches, const PoseOptions& options) {
  const double cap = options.refine_inlier_factor * options.threshold;
  double cost = 0.0;
  for (double e : PoseSampsonErrors(pose.R, pose.t, matches)) {
    const double r = std::min(e, cap) / options.threshold;
    cost += std::log1p(r * r);
  }
  return cost;
}

double PoseCost(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                const std::vector<cv::Point2f>& to, const PoseOptions& options) {
  return PoseCost(pose, NormalizedMatches(camera, from, to), options);
}

namespace {

// One USAC run on normalised points, decomposed.
RelativePose EssentialHypothesis(const std::vector<cv::Point2d>& y_from, const std::vector<cv::Point2d>& y_to,
                                 double normalised_threshold, const PoseOptions& options, int seed) {
  RelativePose pose;
  cv::UsacParams params = SeededUsacParams(options.confidence, options.max_iterations, normalised_threshold, seed);
  params.score = cv::SCORE_METHOD_MSAC;
  // No local optimisation inside USAC: the refinement after it does that on the matches' geometric error,
  // and the dropped LO saved a third of the time with the same poses on kitti07 and redkitchen.
  params.loMethod = cv::LOCAL_OPTIM_NULL;
  cv::Mat mask;
  cv::Mat E;
  try {
    const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F);
    E = cv::findEssentialMat(y_from, y_to, identity, identity, cv::noArray(), cv::noArray(), mask, params);
  } catch (const cv::Exception&) {
    return pose;  // degenerate input (e.g. every match on one point): no model
  }
  if (E.empty() || E.rows < 3 || E.cols != 3 || mask.total() != y_from.size()) return pose;
  if (cv::countNonZero(mask) < options.min_matches) return pose;
  E = E.rowRange(0, 3).clone();
  pose = Decompose(E, y_from, y_to, std::vector<unsigned char>(mask.begin<unsigned char>(), mask.end<unsigned char>()));
  if (pose.num_inliers < options.min_matches) pose.valid = false;
  return pose;
}

}  // namespace

RelativePose EstimateRelativePose(const Camera& camera, const std::vector<cv::Point2f>& from,
                                  const std::vector<cv::Point2f>& to, const PoseOptions& options,
                                  const std::vector<RelativePose>& extra_starts, std::vector<PoseMinimum>* minima) {
  return EstimateRelativePose(NormalizedMatches(camera, from, to), options, extra_starts, minima);
}

RelativePose EstimateRelativePose(const NormalizedMatches& matches, const PoseOptions& options,
                                  const std::vector<RelativePose>& extra_starts, std::vector<PoseMinimum>* minima) {
  if (minima) minima->clear();
  if (static_cast<int>(matches.size()) < options.min_matches) return RelativePose();
  // The threshold is a distance in pixels; on normalised points it is divided by the focal length.
  const double normalised_threshold = options.threshold / matches.focal();
  std::vector<RelativePose> starts;
  for (int k = 0; k < options.starts; ++k) {
    starts.push_back(EssentialHypothesis(matches.from, matches.to, normalised_threshold, options, options.seed + k));
  }
  starts.insert(starts.end(), extra_starts.begin(), extra_starts.end());
  RelativePose best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const RelativePose& start : starts) {
    if (!start.valid) continue;
    const RelativePose refined =
        options.refine
            ? RefineRelativePose(start, matches, options.refine_inlier_factor * options.threshold, options.threshold)
            : start;
    // The refinement minimises errors that are the same for t and -t: it may end pointing backwards.
    const RelativePose candidate = EnforceCheirality(refined, matches, options.threshold);
    const double cost = PoseCost(candidate, matches, options);
    if (minima) minima->push_back({candidate, cost});
    if (cost < best_cost) {  // ties keep the earlier start: deterministic
      best_cost = cost;
      best = candidate;
    }
  }
  return best;
}

double RivalCostGap(const std::vector<PoseMinimum>& minima, double min_angle_deg) {
  const auto cheapest = std::min_element(minima.begin(), minima.end(),
                                         [](const PoseMinimum& a, const PoseMinimum& b) { return a.cost < b.cost; });
  double gap = std::numeric_limits<double>::infinity();
  if (cheapest == minima.end()) return gap;
  for (const PoseMinimum& minimum : minima) {
    if (AngleBetweenDeg(minimum.pose.t, cheapest->pose.t) > min_angle_deg) {
      gap = std::min(gap, minimum.cost - cheapest->cost);
    }
  }
  return gap;
}

std::vector<PoseMinimum> ProbeTranslation(const RelativePose& pose, const Camera& camera,
                                          const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                                          const PoseOptions& options, double angle_deg) {
  if (!pose.valid) return {};
  return ProbeTranslation(pose, NormalizedMatches(camera, from, to), options, angle_deg);
}

std::vector<PoseMinimum> ProbeTranslation(const RelativePose& pose, const NormalizedMatches& matches,
                                          const PoseOptions& options, double angle_deg) {
  std::vector<PoseMinimum> ends;
  if (!pose.valid) return ends;
  const cv::Vec3d t = cv::normalize(pose.t);
  const cv::Vec3d axis = std::abs(t[0]) < 0.9 ? cv::Vec3d(1, 0, 0) : cv::Vec3d(0, 1, 0);
  const cv::Vec3d b0 = cv::normalize(t.cross(axis)), b1 = t.cross(b0);
  const double angle = angle_deg * CV_PI / 180.0;
  for (const cv::Vec3d& direction : {b0, -b0, b1, -b1}) {
    RelativePose start = pose;
    start.t = std::cos(angle) * t + std::sin(angle) * direction;
    const RelativePose refined =
        options.refine
            ? RefineRelativePose(start, matches, options.refine_inlier_factor * options.threshold, options.threshold)
            : start;
    const RelativePose end = EnforceCheirality(refined, matches, options.threshold);
    ends.push_back({end, PoseCost(end, matches, options)});
  }
  return ends;
}

RelativePose PoseFromFundamental(const cv::Matx33d& F, const NormalizedMatches& matches) {
  const cv::Matx33d E = matches.K.t() * F * matches.K;
  return Decompose(cv::Mat(E), matches.from, matches.to, {});
}

RelativePose PoseFromFundamental(const cv::Matx33d& F, const Camera& camera, const std::vector<cv::Point2f>& from,
                                 const std::vector<cv::Point2f>& to) {
  return PoseFromFundamental(F, NormalizedMatches(camera, from, to));
}

cv::Matx33d CrossMatrix(const cv::Vec3d& v) { return cv::Matx33d(0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0); }

cv::Matx33d FundamentalFromPose(const cv::Matx33d& R, const cv::Vec3d& t, const cv::Matx33d& K) {
  const cv::Matx33d Kinv = K.inv();
  return Kinv.t() * CrossMatrix(t) * R * Kinv;
}

double RotationAngleDeg(const cv::Matx33d& R) {
  // The cosine alone (acos of (tr R - 1) / 2) loses small angles, since it changes with their square: a matrix
  // rounded a 1e-7 below orthonormal read as 0.05 degrees. The sine, from the skew-symmetric part, keeps them,
  // and is zero for the symmetric error that rounding leaves.
  const double s = 0.5 * cv::norm(cv::Vec3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1)));
  const double c = (cv::trace(R) - 1.0) / 2.0;
  return std::atan2(s, c) * 180.0 / CV_PI;
}

double AngleBetweenDeg(const cv::Vec3d& a, const cv::Vec3d& b) {
  const double na = cv::norm(a), nb = cv::norm(b);
  if (!(na > 0 && nb > 0)) return 180.0;
  // atan2 of |a x b| and a.b is accurate for small angles, where acos is not.
  return std::atan2(cv::norm(a.cross(b)), a.dot(b)) * 180.0 / CV_PI;
}

std::vector<double> Displacements(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                                  const Camera* camera, const cv::Matx33d* R) {
  CV_Assert(from.size() == to.size());
  std::vector<double> displacements;
  displacements.reserve(from.size());
  if (!camera || !R) {
    for (size_t i = 0; i < from.size(); ++i) displacements.push_back(cv::norm(to[i] - from[i]));
    return displacements;
  }
  return Displacements(NormalizedMatches(*camera, from, to), *R);
}

std::vector<double> Displacements(const NormalizedMatches& matches, const cv::Matx33d& R) {
  std::vector<double> displacements;
  displacements.reserve(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    // Where the point would be seen after the rotation alone (the infinite homography K R K^-1).
    const cv::Vec3d rotated = R * cv::Vec3d(matches.from[i].x, matches.from[i].y, 1.0);
    if (!(rotated[2] > 1e-9)) {
      displacements.push_back(std::numeric_limits<double>::infinity());
      continue;
    }
    const double dx = matches.fx * (matches.to[i].x - rotated[0] / rotated[2]);
    const double dy = matches.fy * (matches.to[i].y - rotated[1] / rotated[2]);
    displacements.push_back(std::hypot(dx, dy));
  }
  return displacements;
}

bool ParsePoseMatches(const std::string& name) {
  const std::optional<bool> all = FindEnum(kPoseMatchesNames, name);
  if (!all)
    throw InputError("unknown pose matches '" + name + "'; use all (every tentative match) or verified (F's inliers)");
  return *all;
}

void PoseOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"method", "--pose",
                 "Relative pose of each link, with a camera: essential (E on normalised points) or "
                 "fundamental (E = K^T F K)"},
                EnumField(method, kPoseMethodNames, ParsePoseMethod));
  visitor.Visit(OptionField{"threshold", "--pose-threshold", "Inlier threshold of the essential matrix, pixels"}
                    .Within(0, 100)
                    .ExcludingMin()
                    .Unit("px"),
                threshold);
  visitor.Visit(OptionField{"matches", "--pose-matches",
                            "Matches the essential matrix is estimated on: all (tentative) or verified (F's inliers)"}
                    .Named("use_all_matches"),
                EnumField(use_all_matches, kPoseMatchesNames, ParsePoseMatches));
  visitor.Visit(OptionField{"confidence"}.Within(0, 1).ExcludingMin().ExcludingMax(), confidence);
  visitor.Visit(OptionField{"max_iterations"}.AtLeast(1), max_iterations);
  visitor.Visit({"seed"}, seed);
}

}  // namespace vmap
