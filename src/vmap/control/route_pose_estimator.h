#pragma once
// Where the robot is on a metric route (TaughtRoute::metric(): the teach run had odometry): its pose in the teach
// odometry's frame, estimated by an extended Kalman filter. The key images are landmarks whose poses the teach
// odometry gives; a localized frame measures the robot's heading against a key image (the features' heading)
// and, where the relative pose's translation is known, the bearing to where that key image was taken. Between
// frames the robot's motion (odometry, or the commands) moves the estimate.
//
// Any key image the localizer compared the frame with is a valid landmark, whether or not it is the one the
// robot is at: a localizer a key image behind or ahead still gives true bearings. A measurement far from what
// the estimate predicts (beyond `gate` standard deviations) is refused, as an outlier.

#include <opencv2/core.hpp>

namespace vmap {

struct RoutePoseEstimatorOptions {
  double heading_sigma = 0.02;          // rad: a frame's heading against a key image, from the relative pose
  double feature_heading_sigma = 0.08;  // rad: the same from the features' heading (biased by parallax)
  double bearing_sigma = 0.06;          // rad: the bearing to a key image from a relative pose
  double gate = 3.0;                    // standard deviations beyond which a measurement is refused
  // Motion noise: of the distance driven (relative), of the turn (relative) and of the heading per metre (slip).
  double distance_noise = 0.05;
  double turn_noise = 0.05;
  double heading_noise_per_metre = 0.02;
  // Position noise per metre driven, either way: what the motion model leaves out (wheel slip, a teach path
  // recorded with its own odometry's errors). It keeps the estimate from growing so sure of itself that it
  // refuses the bearings that would correct it.
  double position_noise_per_metre = 0.05;
  // After this many measurements in a row refused by the gate, the estimate is taken to have gone wrong: its
  // position uncertainty is widened to `recovery_sigma` metres so that the next measurements pull it back.
  int refusals_before_recovery = 1000000;
  double recovery_sigma = 0.5;
};

class RoutePoseEstimator {
 public:
  explicit RoutePoseEstimator(RoutePoseEstimatorOptions options = {}) : options_(options) {}

  bool initialized() const { return initialized_; }
  // Starts at (x, y, yaw) with these standard deviations (metres, metres, radians).
  void Initialize(const cv::Vec3d& pose, const cv::Vec3d& sigma);
  void Reset() { initialized_ = false; }

  // The robot drove `distance` metres (negative: backwards) while turning by `turn` radians.
  void Predict(double distance, double turn);
  // Measurements; each returns whether it was taken (false: refused by the gate, or not initialized).
  bool UpdateHeading(double yaw, double sigma);
  bool UpdateBearing(const cv::Point2d& landmark, double bearing);

  const cv::Vec3d& pose() const { return pose_; }  // x, y, yaw
  const cv::Matx33d& covariance() const { return covariance_; }

 private:
  // One scalar measurement with Jacobian H and innovation `residual`, variance r.
  bool Update(const cv::Matx13d& H, double residual, double r);

  RoutePoseEstimatorOptions options_;
  bool initialized_ = false;
  int refused_in_a_row_ = 0;
  cv::Vec3d pose_;
  cv::Matx33d covariance_ = cv::Matx33d::eye();
};

}  // namespace vmap
