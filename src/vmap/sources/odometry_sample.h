#pragma once
// One pose of a robot's odometry (sources/odometry.h), apart from its readers: a frame carries the robot's pose at
// its time (sources/frame_source.h) without the recordings' headers.

namespace vmap {

// The robot's pose in the plane of its odometry frame at a time (REP 103: x forward, y left, yaw counter-clockwise
// seen from above).
struct OdometrySample {
  double timestamp = 0.0;  // seconds, on the clock of the frames' timestamps
  double x = 0.0;          // metres
  double y = 0.0;
  double yaw = 0.0;  // radians
};

}  // namespace vmap
