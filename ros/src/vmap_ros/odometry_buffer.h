#pragma once
// The robot's recent odometry (nav_msgs/Odometry as it arrives), for the controller to read at each camera frame's
// time: interpolated between the samples around it, or the last one when the frame is a little newer.

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

#include "vmap/sources/odometry.h"

namespace vmap::ros_node {

class OdometryBuffer {
 public:
  // Samples older than `keep_seconds` before the newest are dropped; a frame more than `max_gap_seconds` past the
  // newest sample (odometry that stopped) gets none.
  explicit OdometryBuffer(double keep_seconds = 10.0, double max_gap_seconds = 0.5)
      : keep_seconds_(keep_seconds), max_gap_seconds_(max_gap_seconds) {}

  // Samples in time order: one a little older than the newest (out of order) is ignored; one more than
  // kRestartSeconds older restarts the buffer (a bag played in a loop, a clock reset, or the newest a stray stamp from
  // the future, after which every sample was ignored for good), and Add returns true.
  static constexpr double kRestartSeconds = 1.0;
  bool Add(const OdometrySample& sample);
  std::optional<OdometrySample> At(double timestamp) const;
  // Waits up to `seconds` for a sample at or after `timestamp` while the newest is before it and the odometry still
  // comes (the newest within the gap At accepts): a frame whose odometry travels on another connection reads the
  // sample of its own time, not the one before it.
  void WaitFor(double timestamp, double seconds) const;
  void Clear();

 private:
  double keep_seconds_;
  double max_gap_seconds_;
  mutable std::mutex mutex_;
  mutable std::condition_variable added_;
  std::deque<OdometrySample> samples_;
};

}  // namespace vmap::ros_node
