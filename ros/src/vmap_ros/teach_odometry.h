#pragma once
// The teach run's odometry beside its map: a teach run whose robot publishes odometry writes it into the map folder,
// and a repeat run on the map reads it (pipelines/localize_odometry.h: ReadTeachOdometry) for the taught speeds and
// turns (control/taught_route.h) and the localizer's pace. Its clock is the key images' (both come from the robot's
// ROS clock).

#include <filesystem>
#include <vector>

#include "vmap/pipelines/localize_odometry.h"  // kTeachOdometryFileName
#include "vmap/sources/odometry.h"

namespace vmap::ros_node {

// Writes `samples` as the map folder's teach odometry (a CSV as `vmap localize --odometry` reads it), atomically.
void WriteTeachOdometry(const std::filesystem::path& map, const std::vector<OdometrySample>& samples);

}  // namespace vmap::ros_node
