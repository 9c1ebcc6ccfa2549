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

#include <deque>
#include <limits>

#include <opencv2/core.hpp>

namespace vmap {

struct RoutePoseEstimatorOptions {
  double heading_sigma = 0.02;          // rad: a frame's heading against a key image, from the relative pose
  double feature_heading_sigma = 0.08;  // rad: the same from the features' heading (biased by parallax)
  double bearing_sigma = 0.06;          // rad: the bearing to a key image from a relative pose
  double gate = 3.0;                    // standard deviations beyond which a measurement is refused
  // A comparison that verifies fewer than `weak_share` of the map link's verified matches (the appearance differs
  // from the teach run's: another season, other light) gives measurements unsure by `weak_bearing_sigma` and
  // `weak_heading_sigma` instead. Measured in the simulator (straight route, michigan textures, XFeat, 4 trials
  // each way, docs/drive.md), whatever the pose's translation sigma said: the bearings' errors had a median of 0.01
  // rad where the share was 0.5 or more (same appearance), 0.14-0.22 rad where it was 0.1-0.5 (another season);
  // the rotation's heading 0.002 and 0.033 rad. Taken with the same-appearance sigmas, the true ones were refused by
  // the gate and the wrong ones pulled the estimate across the path (3 of 10 trials reached the goal).
  double weak_share = 0.5;
  double weak_bearing_sigma = 0.25;
  double weak_heading_sigma = 0.05;
  // Along the route: how large the key image's scene appears in the frame (ApparentLogScale of the verified
  // matches) against how much it grows over the map's link into the key image says how far before (smaller) or
  // past (larger) the key image the robot is, unsure by `scale_sigma` metres (`weak_scale_sigma` for a weak
  // comparison). Measured in the simulator (straight route, 4 and 10 trials, the robot's distance to the key
  // image against a line fitted to the log-scales): residuals of 0.02 m median (0.09 m at 90 %) in the teach run's
  // appearance, 0.16 m (0.39 m) across seasons. Without it the bearings alone, which measure across their line of
  // sight, left the estimate of some cross-season runs a key image (0.66 m) ahead of the robot from a
  // relocalization one key image ahead at the start, and every bearing near a key image was then refused.
  // Only on links turning by at most `scale_max_turn` (rad): in a bend the key image looks at a wall beside the
  // path, whose growth is no measure of the distance along it (measured: with it on every link, the s-curve's
  // trials' estimates ran 0.2-0.9 m off along the route, and 8/10 reached the goal instead of 9/10).
  // 0: not measured.
  double scale_sigma = 0.1;
  double weak_scale_sigma = 0.3;
  double scale_max_turn = 0.1;
  // The scene's growth is not a straight line in the distance: a scene `depth` metres ahead of the key image grows
  // as depth / (depth - d) at d metres past it (RoutePoseEstimator::UpdateScale), the depth from the growth over the
  // link. Fitted as a straight line over the link (a rate per metre), it read the s-curve's robot 0.1-0.2 m farther
  // past its first key image than it was 0.5-0.9 m past it, and the estimate entered the bend ahead of the robot.
  // Past the key image the nearest of its scene leaves the view and the rest grows slower than that: measured in the
  // simulator (50 trials a route, the median log-scale against the true distance, the depth fitted before the key
  // image), up to 0.06 m short at 0.3 m past, 0.04-0.12 m short at 0.5 m; a bias the filter would take for the
  // odometry's scale. So taken at most `scale_max_past` metres past the key image (docs/drive.md).
  double scale_max_past = 0.3;
  // Motion noise: of the distance driven (relative), of the turn (relative) and of the heading per metre (slip).
  double distance_noise = 0.05;
  double turn_noise = 0.05;
  double heading_noise_per_metre = 0.02;
  // Position noise per metre driven, either way: what the motion model leaves out (wheel slip, a teach path
  // recorded with its own odometry's errors). It keeps the estimate from growing so sure of itself that it
  // refuses the bearings that would correct it.
  double position_noise_per_metre = 0.05;
  // Recovery: when at least `recovery_refused` of the last `recovery_window` heading measurements were refused by
  // the gate, the estimate is taken to have grown sure of a wrong heading (then every true heading looks like an
  // outlier, and the odometry carries the error into the position): its heading uncertainty is widened to
  // `recovery_heading_sigma` so that the next headings pull it back. Only the heading: a position widened as
  // well let wrong bearings (the corridor's end wall filling the view) throw the estimate across the corridor.
  // recovery_window 0: never, the default: in the simulator it let the end wall's wrong headings in over the last
  // metres of the straight route (docs/drive.md, "Measured behaviour").
  int recovery_window = 0;
  int recovery_refused = 8;
  double recovery_heading_sigma = 0.3;
  // A bearing whose correction would move the estimate along the line of sight to the key image by more than this
  // share of the distance to it is not taken: a bearing measures the position across that line, and its
  // linearization does not hold that far along it (close to the key image with a wide uncertainty along the line
  // of sight, a bearing's small error would throw the estimate metres along it).
  double max_bearing_step_share = 0.3;
  // The start (RouteTracking): the estimate begins between the localizer's key images, unsure by one key
  // image spacing along the route (`start_along_share` of it, at least 0.5 m) and by `start_lateral_sigma`
  // metres across it.
  double start_along_share = 1.0;
  double start_lateral_sigma = 0.35;
  // The frame's heading from the relative pose's rotation is taken only where it agrees with the features'
  // heading within this (rad); otherwise the frame gives no heading (the rotation may be wrong, and the features'
  // heading is biased by the parallax of a sideways offset: taken instead, it pulled the estimate to the wrong
  // side of the path).
  double rotation_agreement = 0.15;
  // The odometry's scale (true distance / measured distance) is estimated with the pose: it starts at 1, unsure
  // by `odometry_scale_sigma`, and may drift by `odometry_scale_drift_per_metre` per metre driven. A wheel a little
  // larger than its nominal size makes every distance too long; with the scale fixed at 1 the estimate runs ahead
  // of the robot, and in a bend the path-following law then turns early (a loop driven with the odometry 5 % too
  // long ended 0.1-0.2 m inside the path). 0: the scale stays 1. 5 %, not 3 %: with 3 % the turn reached its goal
  // in 8/10 and, with the odometry 5 % too long, 5/10 trials, against 10/10 and 9/10 (docs/drive.md).
  double odometry_scale_sigma = 0.05;
  double odometry_scale_drift_per_metre = 0.002;
};

class RoutePoseEstimator {
 public:
  explicit RoutePoseEstimator(RoutePoseEstimatorOptions options = {}) : options_(options) {}

  bool initialized() const { return initialized_; }
  // Starts at (x, y, yaw) with these standard deviations (metres, metres, radians), the odometry's scale at 1.
  void Initialize(const cv::Vec3d& pose, const cv::Vec3d& sigma);
  // The same with a full covariance (x, y, yaw).
  void InitializeWithCovariance(const cv::Vec3d& pose, const cv::Matx33d& covariance);
  void Reset() { initialized_ = false; }

  // The odometry says the robot drove `distance` metres (negative: backwards) while turning by `turn` radians.
  void Predict(double distance, double turn);
  // Measurements; each returns whether it was taken (false: refused by the gate, or not initialized).
  bool UpdateHeading(double yaw, double sigma);
  // The log-scale at which the scene of a key image taken at `landmark`, looking along `direction` (unit), appears
  // when the robot is d metres past the landmark along `direction`: a scene `depth` metres ahead of the landmark
  // grows as depth / (depth - d), so log(depth / (depth - d)); unsure by `sigma` metres along `direction`. Not taken
  // where it says the robot is more than RoutePoseEstimatorOptions::scale_max_past past the landmark.
  bool UpdateScale(const cv::Point2d& landmark, const cv::Vec2d& direction, double depth, double log_scale,
                   double sigma);
  // `sigma` (rad): the bearing's uncertainty; NaN: RoutePoseEstimatorOptions::bearing_sigma.
  bool UpdateBearing(const cv::Point2d& landmark, double bearing,
                     double sigma = std::numeric_limits<double>::quiet_NaN());
  // How many times the estimate's uncertainty was widened since it started (RoutePoseEstimatorOptions: recovery).
  int recoveries() const { return recoveries_; }

  cv::Vec3d pose() const { return {state_[0], state_[1], state_[2]}; }          // x, y, yaw
  cv::Matx33d covariance() const { return covariance_.get_minor<3, 3>(0, 0); }  // of the pose
  double odometry_scale() const { return state_[3]; }                           // true distance / odometry's distance

 private:
  // One scalar measurement with Jacobian H (of x, y, yaw, scale) and innovation `residual`, variance r.
  // `max_step`: a correction moving the position farther than this (m) along the unit `max_step_direction` is
  // not taken (and not counted as refused).
  bool Update(const cv::Matx14d& H, double residual, double r,
              double max_step = std::numeric_limits<double>::infinity(), const cv::Vec2d& max_step_direction = {1, 0});
  // Records whether a heading was refused; widens the heading's uncertainty when too many of the last ones were.
  void RememberHeading(bool refused);

  RoutePoseEstimatorOptions options_;
  bool initialized_ = false;
  std::deque<bool> outcomes_;  // the last recovery_window headings: true where refused
  int recoveries_ = 0;
  cv::Vec4d state_;  // x, y, yaw, odometry scale
  cv::Matx44d covariance_ = cv::Matx44d::eye();
};

}  // namespace vmap
