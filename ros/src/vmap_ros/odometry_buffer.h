#pragma once
// The robot's recent odometry (nav_msgs/Odometry as it arrives), for the controller to read at each camera frame's
// time: interpolated between the samples around it, or the last one when the frame is a little newer.

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

  void Add(const OdometrySample& sample);  // samples in time order; an older one than the newest is ignored
  std::optional<OdometrySample> At(double timestamp) const;
  void Clear();

 private:
  double keep_seconds_;
  double max_gap_seconds_;
  mutable std::mutex mutex_;
  std::deque<OdometrySample> samples_;
};

}  // namespace vmap::ros_node
