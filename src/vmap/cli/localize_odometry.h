#pragma once
// The odometry of `vmap localize`'s query: --odometry FILE (a CSV of timestamp,x,y,yaw, or a recording's
// nav_msgs/Odometry topic), or the query recording's own odometry topic when it has one. With it, every frame's
// CSV row gains the columns odometry_x, odometry_y, odometry_yaw, odometry_distance and key_distance (metres
// since the frame reached its key image: control/odometry_progress.h), and the JSON an "odometry" list.

#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "vmap/cli/option_flags.h"
#include "vmap/control/odometry_progress.h"

namespace vmap::cli {

struct OdometryFlags {
  std::string path;   // --odometry
  std::string topic;  // --odometry-topic
};

void AddOdometryOptions(CLI::App* command, OdometryFlags& flags, OptionFlags& option_flags);

// The query's odometry, if it has one (see above). Throws InputError for an odometry file that cannot be read,
// or a topic that is not there.
std::optional<OdometryProgress> OpenQueryOdometry(const OdometryFlags& flags, const std::string& query);

// ",odometry_x,odometry_y,odometry_yaw,odometry_distance,key_distance" and a frame's cells (empty when the
// odometry does not cover the frame).
std::string OdometryCsvColumns();
std::string OdometryCsvCells(const FrameOdometry& odometry);
nlohmann::json OdometryJson(int frame, const FrameOdometry& odometry);

}  // namespace vmap::cli
