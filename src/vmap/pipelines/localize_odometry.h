#pragma once
// The odometry of a localized query: a CSV of timestamp,x,y,yaw or a recording's nav_msgs/Odometry topic
// (LocalizePipelineOptions::odometry), or the query recording's own odometry topic when it has one. With it, every
// frame's CSV row gains the columns odometry_x, odometry_y, odometry_yaw, odometry_distance and key_distance
// (metres since the frame reached its key image: control/odometry_progress.h), and the run's JSON an "odometry"
// list.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/control/odometry_progress.h"

namespace vmap {

// The query's odometry, if it has one: `path` ("" = the query recording's own topic, if any) and its `topic` ("" =
// the only one). Throws InputError for an odometry file that cannot be read, or a topic that is not there
// (OptionError "odometry_topic" for a topic without a recording).
std::optional<OdometryProgress> OpenQueryOdometry(const std::string& path, const std::string& topic,
                                                  const std::string& query);

// The teach run's odometry beside its map: a teach run whose robot publishes odometry writes it into the map folder
// (the ROS node's teach run), on the key images' clock.
inline constexpr const char* kTeachOdometryFileName = "teach_odometry.csv";

// The teach odometry of a run on `map`: `given` (a CSV of timestamp,x,y,yaw, or a recording with `topic`'s
// nav_msgs/Odometry) when it is set, else the map folder's teach_odometry.csv when there is one, else none. Throws
// InputError naming the file when it cannot be read.
std::vector<OdometrySample> ReadTeachOdometry(const std::filesystem::path& map, const std::string& given,
                                              const std::string& topic);
// Writes `samples` as the map folder's teach odometry (the CSV ReadTeachOdometry reads), atomically: the ROS node's
// teach run and the simulator's teach run.
void WriteTeachOdometry(const std::filesystem::path& map, const std::vector<OdometrySample>& samples);

// ",odometry_x,odometry_y,odometry_yaw,odometry_distance,key_distance" and a frame's cells (empty when the
// odometry does not cover the frame).
std::string OdometryCsvColumns();
std::string OdometryCsvCells(const FrameOdometry& odometry);
nlohmann::json OdometryJson(int frame, const FrameOdometry& odometry);

}  // namespace vmap
