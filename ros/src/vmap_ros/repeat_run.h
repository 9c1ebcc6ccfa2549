#pragma once
// A repeat run as the node drives it, without ROS: `vmap localize`'s session (pipelines/localize_pipeline.h: the map
// opened once, the route, the localizer following the map) with each camera frame localized as `vmap localize`
// localizes a recording's frames (the same frames give the same results), and the route controller
// (control/route_controller.h) turning each localization into a velocity command.

#include <filesystem>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/control/route_controller.h"
#include "vmap/pipelines/localize_pipeline.h"

#include "vmap_ros/camera_messages.h"
#include "vmap_ros/control_clock.h"

namespace vmap::ros_node {

// One frame of a repeat run: where it is, and what the controller commands.
struct RepeatStep {
  LocalizationResult localization;
  ControlStep control;
};

class RepeatRun {
 public:
  // Opens the map of `options` (its key images' features: seconds for a large map without a cache) and the teach
  // run's odometry (`options.session.teach_odometry`, else the map folder's teach_odometry.csv, if any), plans the
  // route from `from` to `to` and sets up the controller on it (the taught profile from the map: the key images'
  // timestamps and the links' poses, or the teach run's odometry when there is one; the localizer paced by it). Throws
  // InputError naming the map and what is wrong (missing, malformed, a key image it has not, no route, no camera and no
  // ~focal_px, a teach odometry that cannot be read) and OptionError for a bad controller option.
  RepeatRun(const LocalizePipelineOptions& options, const ControllerOptions& controller);

  // Localizes the next camera frame of the run (brought to the map's frame size: frame()) and asks the controller
  // for its command at `time` (seconds, the camera's clock), with the robot's odometry at that time when it has one
  // (else null). The odometry also paces the localizer's belief (with the teach odometry: the distance driven between
  // frames). `wall_time`: when the frame arrived (seconds), which keeps the controller's time where the camera's clock
  // does not advance (ControlClock: warned once in a while).
  RepeatStep Step(const CameraImage& image, double time, double wall_time, const OdometrySample* odometry);
  // Localizes the frame only (a paused run keeps its estimate up to date; the controller is not asked).
  LocalizationResult Localize(const CameraImage& image, const OdometrySample* odometry = nullptr);
  // The teach run's odometry (empty: none).
  const std::vector<OdometrySample>& teach_odometry() const { return session_.teach_odometry(); }
  // The controller starts again (after a pause): it commands nothing until a frame is localized.
  void ResetController() { controller_.Reset(); }
  // The robot was stopped outside the controller (RouteController::Stopped).
  void ControllerStopped() { controller_.Stopped(); }

  const VisualMap& map() const { return session_.map(); }
  const std::filesystem::path& directory() const { return session_.opened().directory; }
  // The key images followed, in order (the whole map in its order when no from/to was given).
  const std::vector<int>& route() const { return route_; }
  const LocalizerOptions& options() const { return session_.localizer_options(); }
  int frames() const { return frames_; }
  // The frame last localized, at the map's frame size (the matches' coordinates).
  const Frame& frame() const { return frame_; }

  // Key image `key` of the map as stored (BGR or grey); empty when it cannot be read. Read once, then kept.
  cv::Mat KeyImage(int key);

 private:
  LocalizationSession session_;
  std::vector<int> route_;
  RouteController controller_;
  ControlClock clock_;
  std::vector<cv::Mat> key_images_;
  Frame frame_;
  int frames_ = 0;
};

}  // namespace vmap::ros_node
