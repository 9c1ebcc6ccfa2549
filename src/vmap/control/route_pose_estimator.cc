#include "vmap/control/route_pose_estimator.h"

#include <algorithm>
#include <cmath>

#include "vmap/sources/odometry.h"

namespace vmap {

void RoutePoseEstimator::Initialize(const cv::Vec3d& pose, const cv::Vec3d& sigma) {
  InitializeWithCovariance(pose,
                           cv::Matx33d::diag(cv::Vec3d(sigma[0] * sigma[0], sigma[1] * sigma[1], sigma[2] * sigma[2])));
}

void RoutePoseEstimator::InitializeWithCovariance(const cv::Vec3d& pose, const cv::Matx33d& covariance) {
  state_ = {pose[0], pose[1], WrapAngle(pose[2]), 1.0};
  covariance_ = cv::Matx44d::zeros();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) covariance_(i, j) = covariance(i, j);
  }
  covariance_(3, 3) = options_.odometry_scale_sigma * options_.odometry_scale_sigma;
  initialized_ = true;
  outcomes_.clear();
  recoveries_ = 0;
}

void RoutePoseEstimator::Predict(double distance, double turn) {
  if (!initialized_) return;
  const double scale = state_[3];
  const double middle = state_[2] + 0.5 * turn;
  const double c = std::cos(middle), s = std::sin(middle);
  const double driven = scale * distance;
  state_[0] += driven * c;
  state_[1] += driven * s;
  state_[2] = WrapAngle(state_[2] + turn);
  const cv::Matx44d F(1, 0, -driven * s, distance * c,  //
                      0, 1, driven * c, distance * s,   //
                      0, 0, 1, 0,                       //
                      0, 0, 0, 1);
  // Noise of the distance and the turn, mapped into the pose (G), and a heading slip growing with the distance.
  const cv::Matx<double, 4, 2> G(scale * c, -0.5 * driven * s, scale * s, 0.5 * driven * c, 0, 1, 0, 0);
  const double sd = options_.distance_noise * std::abs(distance) + 1e-4;
  const double st = options_.turn_noise * std::abs(turn) + options_.heading_noise_per_metre * std::abs(distance) + 1e-4;
  const cv::Matx22d noise(sd * sd, 0, 0, st * st);
  covariance_ = F * covariance_ * F.t() + G * noise * G.t();
  const double slip = options_.position_noise_per_metre * std::abs(distance);
  covariance_(0, 0) += slip * slip;
  covariance_(1, 1) += slip * slip;
  if (options_.odometry_scale_sigma > 0.0) {
    const double drift = options_.odometry_scale_drift_per_metre * std::abs(distance);
    covariance_(3, 3) += drift * drift;
  }
}

void RoutePoseEstimator::RememberHeading(bool refused) {
  if (options_.recovery_window <= 0) return;
  outcomes_.push_back(refused);
  if (static_cast<int>(outcomes_.size()) > options_.recovery_window) outcomes_.pop_front();
  const int refusals = static_cast<int>(std::count(outcomes_.begin(), outcomes_.end(), true));
  if (refusals < options_.recovery_refused) return;
  covariance_(2, 2) = std::max(covariance_(2, 2), options_.recovery_heading_sigma * options_.recovery_heading_sigma);
  outcomes_.clear();
  ++recoveries_;
}

bool RoutePoseEstimator::Update(const cv::Matx14d& H, double residual, double r, double max_step,
                                const cv::Vec2d& max_step_direction) {
  const double innovation_variance = (H * covariance_ * H.t())(0, 0) + r;
  if (residual * residual > options_.gate * options_.gate * innovation_variance) {
    return false;
  }
  const cv::Matx41d K = covariance_ * H.t() * (1.0 / innovation_variance);
  if (std::abs(K(0, 0) * residual * max_step_direction[0] + K(1, 0) * residual * max_step_direction[1]) > max_step)
    return false;
  for (int i = 0; i < 4; ++i) state_[i] += K(i, 0) * residual;
  state_[2] = WrapAngle(state_[2]);
  // A scale beyond three of its standard deviations is not an odometry's but wrong bearings' (taken while the
  // estimate was unsure, they put it at 0.5 in an s-curve repeat, and the estimate fell metres behind the robot).
  const double scale_bound = 3.0 * options_.odometry_scale_sigma;
  state_[3] = std::clamp(state_[3], 1.0 - scale_bound, 1.0 + scale_bound);
  covariance_ = (cv::Matx44d::eye() - K * H) * covariance_;
  covariance_ = 0.5 * (covariance_ + covariance_.t());
  return true;
}

bool RoutePoseEstimator::UpdateHeading(double yaw, double sigma) {
  if (!initialized_) return false;
  const bool taken = Update(cv::Matx14d(0, 0, 1, 0), WrapAngle(yaw - state_[2]), sigma * sigma);
  RememberHeading(!taken);
  return taken;
}

bool RoutePoseEstimator::UpdateScale(const cv::Point2d& landmark, const cv::Vec2d& direction, double depth,
                                     double log_scale, double sigma) {
  if (!initialized_ || !(depth > 0.0) || !(sigma > 0.0) || !std::isfinite(log_scale)) return false;
  const double past = (state_[0] - landmark.x) * direction[0] + (state_[1] - landmark.y) * direction[1];
  const double remaining = depth - past;  // from the robot to the scene, as the estimate has it
  // How far past the measurement says (not the estimate: an estimate a key image ahead must still be pulled back).
  const double measured_past = -depth * std::expm1(-log_scale);
  if (!(measured_past <= options_.scale_max_past) || !(remaining >= 0.5 * depth)) return false;
  const double slope = 1.0 / remaining;  // of the log-scale, per metre past the landmark
  return Update(cv::Matx14d(slope * direction[0], slope * direction[1], 0.0, 0.0),
                log_scale - std::log(depth / remaining), (slope * sigma) * (slope * sigma));
}

bool RoutePoseEstimator::UpdateBearing(const cv::Point2d& landmark, double bearing, double sigma) {
  if (!initialized_) return false;
  const double dx = landmark.x - state_[0], dy = landmark.y - state_[1];
  const double range_squared = dx * dx + dy * dy;
  if (range_squared < 0.01) return false;  // a landmark under the robot gives no bearing
  const double predicted = WrapAngle(std::atan2(dy, dx) - state_[2]);
  const cv::Matx14d H(dy / range_squared, -dx / range_squared, -1.0, 0.0);
  const double range = std::sqrt(range_squared);
  if (!std::isfinite(sigma)) sigma = options_.bearing_sigma;
  return Update(H, WrapAngle(bearing - predicted), sigma * sigma, options_.max_bearing_step_share * range,
                cv::Vec2d(dx / range, dy / range));
}

}  // namespace vmap
