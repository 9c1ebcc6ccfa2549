#pragma once
// The controller's clock in a repeat run: the camera's stamps while they advance, else the wall clock.
//
// The route controller measures its acceleration limits and the slowdown of a robot that lost its way (lost_stop)
// in the time between its frames. A camera whose clock went back (a bag played in a loop, a clock reset) or that
// reads 0 (/use_sim_time without /clock) gave it no time at all: a robot lost at that moment crept on, its command
// falling by 0.0003 m/s a frame, for a minute. Such a frame advances the controller by the wall-clock time since the
// frame before instead.

#include <optional>

namespace vmap::ros_node {

// A frame's step of the controller's clock is at most this (seconds): a jump of the camera's clock forward is a gap
// in the frames (the camera timeout's business), not time the robot drove.
inline constexpr double kMaxControlStep = 1.0;
// ... and at least this: two frames with one stamp still advance it.
inline constexpr double kMinControlStep = 1e-3;

class ControlClock {
 public:
  // The controller's time for a frame stamped `camera_seconds` that arrived at `wall_seconds` (the first frame's is its
  // camera stamp). Sets `*by_wall_clock` when the camera's stamp did not advance, so that the caller can say so.
  double Tick(double camera_seconds, double wall_seconds, bool* by_wall_clock);

 private:
  std::optional<double> camera_before_;
  std::optional<double> wall_before_;
  double time_ = 0.0;
};

}  // namespace vmap::ros_node
