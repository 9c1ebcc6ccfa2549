#include "vmap/control/odometry_progress.h"

#include <cmath>

namespace vmap {

FrameOdometry OdometryProgress::Update(const LocalizationResult& result) {
  FrameOdometry odometry;
  const std::optional<OdometrySample> pose = result.timestamp >= 0.0 ? track_.At(result.timestamp) : std::nullopt;
  if (!pose) return odometry;
  odometry.valid = true;
  odometry.pose = *pose;
  odometry.distance = track_.DistanceAt(result.timestamp);
  const bool located = IsPlaced(result.status);
  if (located && result.key >= 0 && result.key != key_) {
    key_ = result.key;
    key_reached_at_ = odometry.distance;
  }
  if (std::isfinite(key_reached_at_)) odometry.key_distance = odometry.distance - key_reached_at_;
  return odometry;
}

}  // namespace vmap
