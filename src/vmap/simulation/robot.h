#pragma once
// A differential-drive robot with a forward-looking pinhole camera: it executes velocity commands with
// actuation noise, and integrates its wheel odometry with a scale error, noise and a yaw-rate bias, as a real
// one does.

#include <random>

#include <opencv2/core.hpp>

#include "vmap/control/route_controller.h"
#include "vmap/core/option_fields.h"
#include "vmap/simulation/plane_renderer.h"
#include "vmap/simulation/route_path.h"
#include "vmap/sources/odometry.h"

namespace vmap {

struct CameraRigOptions {
  int width = 640;  // pixels
  int height = 480;
  double horizontal_fov_deg = 70.0;
  double mount_height = 0.5;  // metres above the floor
  double pitch_deg = 0.0;     // positive: tilted down

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// The camera's intrinsics (square pixels, principal point at the image centre) and its pose on a robot at `pose`.
cv::Matx33d CameraMatrix(const CameraRigOptions& options);
PinholeView CameraView(const CameraRigOptions& options, const Pose2d& pose);

struct RobotNoiseOptions {
  double speed_noise = 0.02;          // relative standard deviation of the executed speed (per step)
  double turn_noise = 0.02;           // rad/s standard deviation of the executed turn rate (per step)
  double odometry_scale_error = 0.0;  // odometry measures distances this much too long (0.05 = 5 %)
  double odometry_noise = 0.01;       // relative standard deviation of each odometry step's distance
  double odometry_yaw_bias = 0.0;     // rad/s the odometry's heading drifts

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

class DifferentialDriveRobot {
 public:
  DifferentialDriveRobot(Pose2d pose, const RobotNoiseOptions& noise, unsigned seed);

  // Drives `command` for `dt` seconds (the executed command is the commanded one with noise).
  void Step(const VelocityCommand& command, double dt);

  const Pose2d& pose() const { return pose_; }                  // the truth
  const OdometrySample& odometry() const { return odometry_; }  // what the robot believes
  double time() const { return time_; }

 private:
  Pose2d pose_;
  OdometrySample odometry_;
  double time_ = 0.0;
  RobotNoiseOptions noise_;
  std::mt19937 rng_;
};

}  // namespace vmap
