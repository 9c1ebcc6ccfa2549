#pragma once
// Following a metric taught path (TaughtRoute::path) from an estimate of the robot's pose: where the robot is
// along it, how far to its side and how it is turned, and the turn rate of a linear path-following law.

#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/sources/odometry.h"

namespace vmap {

struct PathLocation {
  double s = 0.0;              // arc length along the path (m)
  double lateral = 0.0;        // the robot's offset, left of the taught heading positive (m)
  double heading_error = 0.0;  // the robot's yaw minus the taught yaw there (rad)
  double curvature = 0.0;      // taught turn per metre driven there (1/m, left positive)
  cv::Point2d point;           // the nearest point of the path
};

class TaughtPath {
 public:
  explicit TaughtPath(const std::vector<OdometrySample>& samples);  // in the order driven; at least two
  double length() const { return arc_.empty() ? 0.0 : arc_.back(); }
  // The arc length at the sample nearest in time to `timestamp`, interpolated.
  double ArcAtTime(double timestamp) const;
  // The nearest point to (x, y) within [s_min, s_max] of arc length (a loop passes a place twice), and the pose
  // relative to it.
  PathLocation Locate(const cv::Vec3d& pose, double s_min, double s_max) const;

 private:
  double YawAt(double s) const;

  std::vector<OdometrySample> samples_;
  std::vector<double> arc_;
};

// The turn rate that brings a robot driving at `speed` (m/s, negative when reversing along the path) onto the
// path: the taught curvature times the speed, less the heading error and lateral offset, each over the
// distance in which the error should decay: e'' + (2 / L) e' + (1 / L^2) e = 0 along the path (critically
// damped, L = `convergence_distance`). The lateral term is capped at one convergence distance so that a robot
// far off turns towards the path, not around.
double PathFollowingTurnRate(const PathLocation& at, double speed, double convergence_distance);

}  // namespace vmap
