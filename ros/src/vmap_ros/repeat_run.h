#pragma once
// A repeat run as the node drives it, without ROS: the map opened for localization, the route to the goal, and
// each camera frame localized against it (as `vmap localize` localizes a recording's frames: the same frames give
// the same results).

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/localization/localization_map.h"
#include "vmap/localization/localizer.h"

#include "vmap_ros/camera_messages.h"

namespace vmap::ros_node {

struct RepeatRequest {
  std::filesystem::path map;  // the map directory
  int goal = -1;              // the key image to reach; -1 = the map's last
  int start = -1;             // the route's first key image; -1 = the map's first
  // The localizer's options (the node's parameters); its verifier, S, translation thresholds and camera follow
  // the map, its route is planned from start to goal.
  LocalizerOptions localizer;
  bool cache = true;  // the key-image cache in the map directory
};

class RepeatRun {
 public:
  // Opens the map (its key images' features: seconds for a large map without a cache) and plans the route. Throws
  // InputError naming the map and what is wrong (missing, malformed, a goal it has not, no route to it).
  explicit RepeatRun(const RepeatRequest& request);
  ~RepeatRun();

  // Localizes the next camera frame of the run (brought to the map's frame size: frame()).
  LocalizationResult Localize(const CameraImage& image);
  // The frame last localized, at the map's frame size (the matches' coordinates).
  const Frame& frame() const { return frame_; }
  // Forgets the estimate: the next frame is relocalized.
  void Reset();

  const VisualMap& map() const { return opened_->map; }
  const std::filesystem::path& directory() const { return opened_->directory; }
  const std::vector<int>& route() const { return options_.route; }
  const LocalizerOptions& options() const { return options_; }
  int frames() const { return frames_; }

  // Key image `key` of the map as stored (BGR or grey); empty when it cannot be read. Read once, then kept.
  cv::Mat KeyImage(int key);

 private:
  std::unique_ptr<LocalizationMap> opened_;
  LocalizerOptions options_;
  std::unique_ptr<Localizer> localizer_;
  std::vector<cv::Mat> key_images_;
  Frame frame_;
  int frames_ = 0;
};

}  // namespace vmap::ros_node
