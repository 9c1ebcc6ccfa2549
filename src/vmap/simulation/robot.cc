#include "vmap/simulation/robot.h"

#include <cmath>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void CameraRigOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Simulated camera");
  visitor.Visit(OptionField{"width", "--camera-width", "Camera image width (pixels)"}.Within(64, 4096).Unit("px"),
                width);
  visitor.Visit(OptionField{"height", "--camera-height", "Camera image height (pixels)"}.Within(48, 4096).Unit("px"),
                height);
  visitor.Visit(
      OptionField{"horizontal_fov_deg", "--fov", "Camera horizontal field of view (degrees)"}.Within(20, 150).Unit(
          "degrees"),
      horizontal_fov_deg);
  visitor.Visit(OptionField{"mount_height", "--camera-mount-height", "Camera height above the floor (m)"}
                    .Within(0, 10)
                    .ExcludingMin()
                    .Unit("m"),
                mount_height);
  visitor.Visit(OptionField{"pitch_deg", "--camera-pitch", "Camera tilt, down positive (degrees)"}.Within(-45, 45).Unit(
                    "degrees"),
                pitch_deg);
}

void CameraRigOptions::Check() const {
  // The mount height is checked against the walls too, by the simulation (SimulationOptions::Check).
  CheckFieldRanges(*this);
}

cv::Matx33d CameraMatrix(const CameraRigOptions& options) {
  const double f = 0.5 * options.width / std::tan(0.5 * options.horizontal_fov_deg * M_PI / 180.0);
  return {f, 0, (options.width - 1) / 2.0, 0, f, (options.height - 1) / 2.0, 0, 0, 1};
}

PinholeView CameraView(const CameraRigOptions& options, const Pose2d& pose) {
  // Camera axes in the world (REP 103: z up): x right, y down, z forward, tilted down by the pitch.
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  const double pitch = options.pitch_deg * M_PI / 180.0;
  const cv::Vec3d forward_flat(c, s, 0), right(s, -c, 0), down(0, 0, -1);
  const cv::Vec3d forward = std::cos(pitch) * forward_flat + std::sin(pitch) * down;
  const cv::Vec3d camera_down = std::cos(pitch) * down - std::sin(pitch) * forward_flat;
  cv::Matx33d R;  // world to camera: rows are the camera's axes
  for (int k = 0; k < 3; ++k) {
    R(0, k) = right[k];
    R(1, k) = camera_down[k];
    R(2, k) = forward[k];
  }
  const cv::Vec3d centre(pose.x, pose.y, options.mount_height);
  return {CameraMatrix(options), cv::Size(options.width, options.height), R, -(R * centre)};
}

void RobotNoiseOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Simulated robot: motion and odometry noise");
  visitor.Visit(
      OptionField{"speed_noise", "--speed-noise", "Actuation: relative standard deviation of the executed speed"}
          .Within(0, 1),
      speed_noise);
  visitor.Visit(
      OptionField{"turn_noise", "--turn-noise", "Actuation: standard deviation of the executed turn rate (rad/s)"}
          .Within(0, 1),
      turn_noise);
  visitor.Visit(OptionField{"odometry_scale_error", "--odometry-scale-error",
                            "Odometry measures distances this much too long (0.05 = 5 %; negative: too short)"}
                    .Within(-0.5, 0.5),
                odometry_scale_error);
  visitor.Visit(
      OptionField{"odometry_noise", "--odometry-noise", "Odometry: relative standard deviation of each step's distance"}
          .Within(0, 1),
      odometry_noise);
  visitor.Visit(
      OptionField{"odometry_yaw_bias", "--odometry-yaw-bias", "Odometry: heading drift (rad/s)"}.Within(-1, 1),
      odometry_yaw_bias);
}

void RobotNoiseOptions::Check() const { CheckFieldRanges(*this); }

DifferentialDriveRobot::DifferentialDriveRobot(Pose2d pose, const RobotNoiseOptions& noise, unsigned seed)
    : pose_(pose), noise_(noise), rng_(seed) {
  odometry_ = {0.0, pose.x, pose.y, pose.yaw};
}

void DifferentialDriveRobot::Step(const VelocityCommand& command, double dt) {
  std::normal_distribution<double> unit(0.0, 1.0);
  const double v = command.linear * (1.0 + noise_.speed_noise * unit(rng_));
  const double w = command.angular + noise_.turn_noise * unit(rng_);
  // Exact unicycle motion over the step (an arc).
  auto advance = [dt](double& x, double& y, double& yaw, double speed, double turn) {
    const double distance = speed * dt, angle = turn * dt;
    const double chord = std::abs(angle) > 1e-9 ? 2.0 * distance / angle * std::sin(0.5 * angle) : distance;
    x += chord * std::cos(yaw + 0.5 * angle);
    y += chord * std::sin(yaw + 0.5 * angle);
    yaw = WrapAngle(yaw + angle);
  };
  advance(pose_.x, pose_.y, pose_.yaw, v, w);
  const double measured = v * (1.0 + noise_.odometry_scale_error) * (1.0 + noise_.odometry_noise * unit(rng_));
  advance(odometry_.x, odometry_.y, odometry_.yaw, measured, w + noise_.odometry_yaw_bias);
  time_ += dt;
  odometry_.timestamp = time_;
}

}  // namespace vmap
