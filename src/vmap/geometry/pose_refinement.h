#pragma once
// The robust Sampson cost of a relative pose over its matches (geometry/relative_pose.h's conventions) and what
// is read from it: each match's error, the pose refined to the cost's nearest minimum, and how well that
// minimum fixes the translation's direction (the cost's curvature).

#include <vector>

#include <opencv2/core.hpp>

#include "vmap/geometry/camera.h"
#include "vmap/geometry/relative_pose.h"

namespace vmap {

// The matches within `threshold` px (Sampson error) of a pose: 1 where within.
std::vector<unsigned char> MatchesWithin(const RelativePose& pose, const NormalizedMatches& matches, double threshold);

// Sampson errors in pixels of matches under a pose (on normalised points, times the mean focal length).
std::vector<double> PoseSampsonErrors(const cv::Matx33d& R, const cv::Vec3d& t, const Camera& camera,
                                      const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to);
std::vector<double> PoseSampsonErrors(const cv::Matx33d& R, const cv::Vec3d& t, const NormalizedMatches& matches);

// Refines a pose by Levenberg-Marquardt (OpenCV's LMSolver) on the Sampson errors, in pixels, of the matches
// within inlier_threshold of it, each through a Cauchy loss of scale `loss_scale` pixels. The translation
// stays a unit vector (two parameters on the sphere); the rotation takes three.
RelativePose RefineRelativePose(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                                const std::vector<cv::Point2f>& to, double inlier_threshold, double loss_scale);
RelativePose RefineRelativePose(const RelativePose& pose, const NormalizedMatches& matches, double inlier_threshold,
                                double loss_scale);

// How well a pose's translation direction is determined by the matches within `inlier_threshold` px of it:
// the standard deviation, in degrees, of t's direction from the Gauss-Newton covariance of the refinement's
// cost (Cauchy-weighted Sampson errors, loss scale `loss_scale` px) at the pose, with the rotation
// marginalised (the larger axis of the 2x2 block) and the noise estimated from the residuals. Short
// baselines and pure rotations leave the cost flat along t: a large value. 180 when it cannot be computed
// (too few matches, a singular system).
double TranslationSigmaDeg(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                           const std::vector<cv::Point2f>& to, double inlier_threshold, double loss_scale);
double TranslationSigmaDeg(const RelativePose& pose, const NormalizedMatches& matches, double inlier_threshold,
                           double loss_scale);

}  // namespace vmap
