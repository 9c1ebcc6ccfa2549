#pragma once
// The relative pose of two calibrated views, and the quantities that tell whether it is well posed.
//
// Conventions (one set, used by every function here, by map.json and by `vmap eval`):
//   the pair is (from, to): a link's first key image is "from", its second is "to";
//   F satisfies x_to^T F x_from = 0 in pixels, E satisfies y_to^T E y_from = 0 in normalised coordinates;
//   the pose (R, t) maps a point's coordinates in the "from" camera to the "to" camera: X_to = R X_from + t,
//   so E = [t]x R. t has unit length (two views fix only the translation's direction); it is where the
//   "from" camera's centre lies in "to" coordinates. A camera moving forward along its optical axis from
//   "from" to "to" therefore gives t = (0, 0, -1).

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/core/option_fields.h"
#include "vmap/geometry/camera.h"

namespace vmap {

enum class PoseMethod {
  kEssential,        // E estimated directly on normalised points (five-point solver in OpenCV's USAC)
  kFromFundamental,  // the link's F turned into E = K^T F K and decomposed
};
inline constexpr EnumName<PoseMethod> kPoseMethodNames[] = {{PoseMethod::kEssential, "essential"},
                                                            {PoseMethod::kFromFundamental, "fundamental"}};
PoseMethod ParsePoseMethod(const std::string& name);
std::string PoseMethodName(PoseMethod method);

struct PoseOptions {
  PoseMethod method = PoseMethod::kEssential;
  // Inlier threshold of the essential-matrix estimation, in pixels (divided by the mean focal length to
  // work on normalised points). Also the scale of the refinement's Cauchy loss.
  double threshold = 1.0;
  // Estimate on every tentative match of the link (true) or only on the verifier's inliers of F (false).
  bool use_all_matches = true;
  // Forward motion and short baselines leave the matches' geometric error with several local minima (a
  // rotation error traded for a translation turned by up to 90 degrees). So the estimate starts from
  // several hypotheses: USAC run with `starts` seeds (seed, seed + 1, ...) and any given start (the pose of
  // F); each is refined, and the one with the lowest robust cost over all the matches wins. 0: only the
  // starts the caller gives.
  int starts = 3;
  // Callers that have the link's F add its pose as one more start (mapping/link_analysis.cc).
  bool start_from_fundamental = true;
  // Refine each start by Levenberg-Marquardt on the Sampson errors of the matches within
  // refine_inlier_factor * threshold, with a Cauchy loss of scale `threshold` (RANSAC's model fits a minimal
  // sample and a linear local optimisation, not the matches' geometric error).
  bool refine = true;
  double refine_inlier_factor = 3.0;
  double confidence = 0.999;  // per start
  int max_iterations = 10000;
  int seed = 0;         // the random generator's state: the same link gives the same pose
  int min_matches = 8;  // fewer inliers than this: no pose

  // The pose options as map.json records them: method, threshold, matches ("all" or "verified"), confidence,
  // max_iterations, seed; the others (starts, refinement) are the algorithm's, not a user's choice.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// The names of PoseOptions::use_all_matches (--pose-matches, map.json's pose.matches).
inline constexpr EnumName<bool> kPoseMatchesNames[] = {{true, "all"}, {false, "verified"}};
bool ParsePoseMatches(const std::string& name);

struct RelativePose {
  bool valid = false;
  cv::Matx33d R = cv::Matx33d::eye();  // X_to = R X_from + t
  cv::Vec3d t;                         // unit length
  int num_inliers = 0;  // matches within the threshold of the pose (and, before refinement, in front of both cameras)
};

// Where one start of EstimateRelativePose ended: its refined (and cheirality-decided) pose and PoseCost.
struct PoseMinimum {
  RelativePose pose;
  double cost = 0.0;
};

// The matches of one pose problem in normalised image coordinates (distortion removed), undistorted once.
// Each function below takes them or, for convenience, pixels and the camera; the pose code undistorts no
// point twice through this (cv::undistortPoints is iterative: a comparison of `vmap localize` spent more on
// undistorting the same points again in each step than on refining the pose).
struct NormalizedMatches {
  NormalizedMatches(const Camera& camera, const std::vector<cv::Point2f>& from_pixels,
                    const std::vector<cv::Point2f>& to_pixels);
  NormalizedMatches Select(const std::vector<unsigned char>& mask) const;  // those where mask != 0
  size_t size() const { return from.size(); }
  double focal() const { return 0.5 * (fx + fy); }  // pixels per normalised unit, for thresholds in pixels

  std::vector<cv::Point2d> from, to;
  double fx = 0.0, fy = 0.0;
  cv::Matx33d K;
};

// E estimated on the normalised points with OpenCV's USAC (MSAC scoring, local optimisation) from
// options.starts seeds, each decomposed with the cheirality check; these and `extra_starts` are refined
// (options.refine), each refined pose is decided again among the four its E allows (EnforceCheirality), and
// the pose with the lowest PoseCost wins. `minima`, when given, receives every valid start's end, in order.
RelativePose EstimateRelativePose(const Camera& camera, const std::vector<cv::Point2f>& from,
                                  const std::vector<cv::Point2f>& to, const PoseOptions& options,
                                  const std::vector<RelativePose>& extra_starts = {},
                                  std::vector<PoseMinimum>* minima = nullptr);
RelativePose EstimateRelativePose(const NormalizedMatches& matches, const PoseOptions& options,
                                  const std::vector<RelativePose>& extra_starts = {},
                                  std::vector<PoseMinimum>* minima = nullptr);

// The starts of EstimateRelativePose can end in different valleys of the matches' cost. Of the minima whose
// translation points more than `min_angle_deg` away from that of the cheapest one (the pose
// EstimateRelativePose returns), how much more the cheapest of them costs (PoseCost units); infinity when
// there is none. A small gap says another pose, with another translation, explains the matches almost as
// well: the direction is ambiguous whatever the curvature at the chosen minimum (TranslationSigmaDeg) says.
double RivalCostGap(const std::vector<PoseMinimum>& minima, double min_angle_deg);

// The starts find a rival only where one of them happens to fall into its valley. This looks for one next to
// the pose: four refinements (as EstimateRelativePose's) started from `pose` with its translation turned by
// `angle_deg` in four directions perpendicular to it. Where the cost is flat along t (a vanishing baseline, a
// rotation that mimics a translation) they stay away from t at almost its cost; where t is well determined
// they return to it or cost clearly more. Their ends, for RivalCostGap beside the starts'.
std::vector<PoseMinimum> ProbeTranslation(const RelativePose& pose, const Camera& camera,
                                          const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                                          const PoseOptions& options, double angle_deg);
std::vector<PoseMinimum> ProbeTranslation(const RelativePose& pose, const NormalizedMatches& matches,
                                          const PoseOptions& options, double angle_deg);

// The robust cost a pose is chosen by: sum over the matches of log(1 + (e / threshold)^2), e the Sampson
// error in pixels capped at refine_inlier_factor * threshold.
double PoseCost(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                const std::vector<cv::Point2f>& to, const PoseOptions& options);
double PoseCost(const RelativePose& pose, const NormalizedMatches& matches, const PoseOptions& options);

// The pose of a fundamental matrix (x_to^T F x_from = 0): E = K^T F K, projected onto the essential
// manifold and decomposed; of the four decompositions the one that puts most of the given matches (F's
// inliers) in front of both cameras wins.
RelativePose PoseFromFundamental(const cv::Matx33d& F, const Camera& camera, const std::vector<cv::Point2f>& from,
                                 const std::vector<cv::Point2f>& to);
RelativePose PoseFromFundamental(const cv::Matx33d& F, const NormalizedMatches& matches);

// The Sampson errors cannot tell the four poses one E = [t]x R allows apart ((R, t), (R, -t) and the twisted
// pair), so a refinement may end at a pose whose t points backwards. This decides among the four again: the
// one that puts most of the matches within `inlier_threshold` px of the pose in front of both cameras (ties
// keep the given pose). num_inliers stays: the four have the same errors.
RelativePose EnforceCheirality(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                               const std::vector<cv::Point2f>& to, double inlier_threshold);
RelativePose EnforceCheirality(const RelativePose& pose, const NormalizedMatches& matches, double inlier_threshold);

// x_to^T F x_from = 0 for the pose (R, t) and a camera K (pixels, distortion removed).
cv::Matx33d FundamentalFromPose(const cv::Matx33d& R, const cv::Vec3d& t, const cv::Matx33d& K);
cv::Matx33d CrossMatrix(const cv::Vec3d& v);

// The angle of a rotation, in degrees; accurate to float precision for small angles too.
double RotationAngleDeg(const cv::Matx33d& R);
// The angle between two directions, in degrees (0 to 180).
double AngleBetweenDeg(const cv::Vec3d& a, const cv::Vec3d& b);

// Per match, how far the point moved between the two images, in pixels. With a camera and a rotation R
// (from -> to), the displacement left after undoing the rotation: |x_to - K R K^-1 x_from| on pinhole pixels
// (distortion removed), which is what triangulation and the translation's direction rest on; a pure rotation
// leaves none. Without a camera, the plain displacement |x_to - x_from|.
std::vector<double> Displacements(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                                  const Camera* camera = nullptr, const cv::Matx33d* R = nullptr);
std::vector<double> Displacements(const NormalizedMatches& matches, const cv::Matx33d& R);

}  // namespace vmap
