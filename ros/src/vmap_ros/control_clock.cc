#include "vmap_ros/control_clock.h"

#include <algorithm>
#include <cmath>

namespace vmap::ros_node {

double ControlClock::Tick(double camera_seconds, double wall_seconds, bool* by_wall_clock) {
  *by_wall_clock = false;
  double step = 0.0;
  if (!camera_before_) {
    time_ = std::isfinite(camera_seconds) ? camera_seconds : 0.0;
  } else {
    const double by_camera = camera_seconds - *camera_before_;
    step = by_camera;
    if (!(by_camera > 0.0 && std::isfinite(by_camera))) {
      *by_wall_clock = true;
      step = wall_seconds - *wall_before_;
    }
    // NaN (a wall clock that is not a number) takes the least step.
    step = std::isfinite(step) ? std::clamp(step, kMinControlStep, kMaxControlStep) : kMinControlStep;
    time_ += step;
  }
  camera_before_ = camera_seconds;
  wall_before_ = wall_seconds;
  return time_;
}

}  // namespace vmap::ros_node
