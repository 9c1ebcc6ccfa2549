#pragma once
// The teach run's odometry beside its map: a teach run whose robot publishes odometry writes it into the map folder,
// and a repeat run on the map reads it for the taught speeds and turns (control/taught_route.h). Its clock is the
// key images' (both come from the robot's ROS clock).

#include <filesystem>
#include <string>
#include <vector>

#include "vmap/sources/odometry.h"

namespace vmap::ros_node {

inline constexpr const char* kTeachOdometryFileName = "teach_odometry.csv";

// Writes `samples` as the map folder's teach odometry (a CSV as `vmap localize --odometry` reads it), atomically.
void WriteTeachOdometry(const std::filesystem::path& map, const std::vector<OdometrySample>& samples);

// The teach odometry of a repeat run on `map`: `given` (~teach_odometry: a CSV, or a recording with `topic`'s
// nav_msgs/Odometry) when it is set, else the map folder's teach_odometry.csv when there is one, else none. Throws
// InputError naming the file when it cannot be read.
std::vector<OdometrySample> TeachOdometryFor(const std::filesystem::path& map, const std::string& given,
                                             const std::string& topic);

}  // namespace vmap::ros_node
