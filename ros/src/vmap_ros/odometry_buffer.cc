#include "vmap_ros/odometry_buffer.h"

#include <algorithm>
#include <chrono>

namespace vmap::ros_node {

bool OdometryBuffer::Add(const OdometrySample& sample) {
  bool restarted = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!samples_.empty() && sample.timestamp <= samples_.back().timestamp) {
      if (sample.timestamp > samples_.back().timestamp - kRestartSeconds) return false;
      samples_.clear();
      restarted = true;
    }
    samples_.push_back(sample);
    while (samples_.front().timestamp < sample.timestamp - keep_seconds_) samples_.pop_front();
  }
  added_.notify_all();
  return restarted;
}

std::optional<OdometrySample> OdometryBuffer::At(double timestamp) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (samples_.empty() || timestamp < samples_.front().timestamp) return std::nullopt;
  if (timestamp >= samples_.back().timestamp) {
    if (timestamp - samples_.back().timestamp > max_gap_seconds_) return std::nullopt;
    OdometrySample last = samples_.back();
    last.timestamp = timestamp;
    return last;
  }
  // The two samples around it, interpolated as the odometry of a recording is (sources/odometry.h).
  const auto after = std::lower_bound(samples_.begin(), samples_.end(), timestamp,
                                      [](const OdometrySample& s, double t) { return s.timestamp < t; });
  if (after == samples_.begin()) return *after;
  return InterpolateOdometry({*(after - 1), *after}, timestamp);
}

void OdometryBuffer::WaitFor(double timestamp, double seconds) const {
  if (!(seconds > 0.0)) return;
  std::unique_lock<std::mutex> lock(mutex_);
  const auto comes = [&] {
    return !samples_.empty() && samples_.back().timestamp < timestamp &&
           timestamp - samples_.back().timestamp <= max_gap_seconds_;
  };
  added_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return !comes(); });
}

void OdometryBuffer::Clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  samples_.clear();
}

}  // namespace vmap::ros_node
