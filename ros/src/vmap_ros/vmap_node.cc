// The vmap node (vmap_node.h): its set-up, the camera's callbacks, the worker, and what teach and repeat share.

#include "vmap_ros/vmap_node.h"

#include <fmt/format.h>
#include <geometry_msgs/Twist.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Bool.h>

#include "vmap/core/error.h"
#include "vmap/pipelines/build_pipeline.h"
#include "vmap/pipelines/localize_pipeline.h"
#include "vmap/sources/recording_source.h"

#include "vmap_ros/Localization.h"
#include "vmap_ros/TeachProgress.h"
#include "vmap_ros/parameter_reader.h"

namespace vmap::ros_node {
namespace {

// The mailbox decides what a repeat run keeps; ROS's own queue only holds messages while no spinner thread is free,
// and would drop them uncounted if it filled up.
constexpr uint32_t kImageQueue = 100;
constexpr std::chrono::milliseconds kWorkerPoll{100};
// A camera that keeps sending one malformed message is logged once every this many seconds.
constexpr double kRepeatedErrorSeconds = 5.0;

// Why the camera of a repeat run does not look like the one the map was taught with (another camera, another
// calibration), or "" when it does: focal lengths within 5 % at the map's frame size.
std::string CameraMismatch(const Camera& live, const Camera& map) {
  Camera scaled = live;
  if (!live.size.empty() && !map.size.empty() && live.size != map.size) {
    try {
      scaled = CameraForFrames(live, live.size, map.size);
    } catch (const InputError& error) {
      return fmt::format("the camera's CameraInfo ({}x{}) does not fit the map's frames ({}x{}): {}", live.size.width,
                         live.size.height, map.size.width, map.size.height, error.what());
    }
  }
  if (std::abs(scaled.fx / map.fx - 1.0) <= 0.05 && std::abs(scaled.fy / map.fy - 1.0) <= 0.05) return "";
  return fmt::format(
      "the camera's CameraInfo has fx {:.1f}, fy {:.1f} at the map's frame size, the map's camera fx {:.1f}, fy "
      "{:.1f}: "
      "was the map taught with another camera or calibration? Headings and poses use the map's",
      scaled.fx, scaled.fy, map.fx, map.fy);
}

}  // namespace

VmapNode::VmapNode(const ros::NodeHandle& node, const ros::NodeHandle& private_node)
    : node_(node), private_node_(private_node) {
  image_topic_ = node_.resolveName("image");
  // The CameraInfo topic: ~camera_topic (vmap build's --camera-topic), camera_info when it is remapped, else the one
  // beside the image topic, as image_transport pairs them.
  std::string camera_topic;
  const std::string remapped = node_.resolveName("camera_info");
  if (private_node_.getParam("camera_topic", camera_topic) && !camera_topic.empty()) {
    camera_info_topic_ = node_.resolveName(camera_topic);
  } else if (remapped != node_.resolveName("camera_info", false)) {
    camera_info_topic_ = remapped;
  } else {
    camera_info_topic_ = CameraInfoTopicFor(image_topic_);
  }

  cmd_vel_ = node_.advertise<geometry_msgs::Twist>("cmd_vel", 1);
  localization_ = private_node_.advertise<vmap_ros::Localization>("localization", 10);
  localized_ = private_node_.advertise<std_msgs::Bool>("localized", 1, /*latch=*/true);
  debug_image_ = private_node_.advertise<sensor_msgs::Image>("debug_image", 1);
  teach_progress_ = private_node_.advertise<vmap_ros::TeachProgress>("teach/progress", 10);
  services_.push_back(private_node_.advertiseService("teach/start", &VmapNode::StartTeach, this));
  services_.push_back(private_node_.advertiseService("teach/stop", &VmapNode::StopTeach, this));
  services_.push_back(private_node_.advertiseService("repeat/start", &VmapNode::StartRepeat, this));
  services_.push_back(private_node_.advertiseService("repeat/pause", &VmapNode::PauseRepeat, this));
  services_.push_back(private_node_.advertiseService("repeat/resume", &VmapNode::ResumeRepeat, this));
  services_.push_back(private_node_.advertiseService("repeat/stop", &VmapNode::StopRepeat, this));
  WarnAboutUnknownParameters(private_node_, KnownParameters());

  worker_ = std::thread([this] { Work(); });
  ROS_INFO("vmap node ready: camera %s (CameraInfo %s); call %s/teach/start or %s/repeat/start", image_topic_.c_str(),
           camera_info_topic_.c_str(), private_node_.getNamespace().c_str(), private_node_.getNamespace().c_str());
}

bool VmapNode::Stop() {
  if (stopped_) return true;
  stopped_ = true;
  stopping_ = true;  // no run starts from here on (ClaimForStart)
  // A start or stop in progress ends first: a teach run it started is finished below, not dropped.
  const std::lock_guard<std::mutex> transition(transitions_mutex_);
  // The worker first: a frame in progress publishes its command before the stop below, never after it.
  mailbox_.Close();
  if (worker_.joinable()) worker_.join();
  std::unique_ptr<TeachRun> teach;
  bool repeating = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    repeating = mode_ == Mode::kRepeating || mode_ == Mode::kPaused;
    if (mode_ == Mode::kTeaching) {
      teach = std::move(teach_);
      mode_ = Mode::kFinishing;
    }
  }
  if (repeating) {
    PublishStop();
    ROS_INFO("the node is stopping during a repeat run: the robot is stopped");
  }
  bool written = true;
  if (teach) {
    ROS_WARN("the node is stopping during a teach run: finishing its map");
    UnsubscribeCamera();
    std::string answer;
    written = FinishTeach(std::move(teach), &answer);
    if (written) {
      ROS_INFO("%s", answer.c_str());
    } else {
      ROS_ERROR("%s", answer.c_str());
    }
  }
  // The stop command is sent by the publisher's connections; a moment for it before ROS goes down.
  if (repeating) ros::WallDuration(0.2).sleep();
  return written;
}

VmapNode::~VmapNode() { Stop(); }

void VmapNode::RefuseRecordingParameters() const {
  // The flags of `vmap build` and `vmap localize` that name what a recording is read from.
  for (const char* name : {"format", "topic", "until_interrupted", "stream_timeout"}) {
    if (private_node_.hasParam(name)) {
      throw InputError(
          fmt::format("~{} is vmap's option for recordings and streams; the node's camera is the `image` topic: "
                      "remap it, and drop ~{}",
                      name, name));
    }
  }
  if (private_node_.hasParam("output")) {
    throw InputError(
        "~output is vmap build's -o; the node's map is the one its request names, or ~map: set that, "
        "and drop ~output");
  }
}

std::vector<std::string> VmapNode::TeachParametersSet() const {
  ParameterNames teach, repeat;
  BuildPipelineOptions build;
  LocalizationSessionOptions session;
  ControllerOptions controller;
  teach.Add(build);
  repeat.Add(session);
  repeat.Add(controller);
  std::vector<std::string> set;
  for (const std::string& name : teach.names()) {
    if (repeat.names().count(name) == 0 && private_node_.hasParam(name)) set.push_back("~" + name);
  }
  if (private_node_.hasParam("teach_queue")) set.push_back("~teach_queue");
  return set;
}

std::set<std::string> VmapNode::KnownParameters() const {
  ParameterNames names;
  BuildPipelineOptions teach;
  LocalizationSessionOptions repeat;
  ControllerOptions controller;
  names.Add(teach);
  names.Add(repeat);
  names.Add(controller);
  std::set<std::string> known = names.names();
  known.insert({"map", "teach_queue", "teach_odometry", "teach_odometry_topic", "camera_timeout", "odom_wait"});
  return known;
}

void VmapNode::SubscribeCamera() {
  image_subscriber_ =
      node_.subscribe(image_topic_, kImageQueue, &VmapNode::OnImage, this, ros::TransportHints().tcpNoDelay());
  camera_info_subscriber_ = node_.subscribe(camera_info_topic_, 1, &VmapNode::OnCameraInfo, this);
}

void VmapNode::UnsubscribeCamera() {
  image_subscriber_.shutdown();
  camera_info_subscriber_.shutdown();
}

void VmapNode::OnImage(const topic_tools::ShapeShifter::ConstPtr& message) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ == Mode::kTeaching) {
      teach_->source().Put(message);
      return;
    }
    if (mode_ != Mode::kRepeating && mode_ != Mode::kPaused) return;
  }
  mailbox_.Put(Arrival{message, ros::WallTime::now()});
}

void VmapNode::OnCameraInfo(const sensor_msgs::CameraInfo::ConstPtr& info) {
  std::optional<Camera> camera;
  try {
    camera = CameraFromInfo(*info, camera_info_topic_);
  } catch (const InputError& error) {
    LogMessageError(std::string(error.what()) + "; the message is ignored", error.what());
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ == Mode::kTeaching) teach_->source().SetCamera(camera);
  }
  std::lock_guard<std::mutex> lock(camera_mutex_);
  camera_ = camera;
  if (camera_checked_ || !camera || !map_camera_) return;
  camera_checked_ = true;
  const std::string problem = CameraMismatch(*camera, *map_camera_);
  if (!problem.empty()) ROS_WARN("%s", problem.c_str());
}

std::string VmapNode::Busy() const {
  switch (mode_) {
    case Mode::kIdle:
      return "";
    case Mode::kStarting:
      return "another run is starting; try again when its start has answered";
    case Mode::kTeaching:
      return fmt::format("a teach run is in progress; call {}/teach/stop first", private_node_.getNamespace());
    case Mode::kFinishing:
      return "a teach run's map is being written; try again when ~teach/stop has answered";
    case Mode::kRepeating:
    case Mode::kPaused:
      break;
  }
  return fmt::format("a repeat run is in progress (goal {}); call {}/repeat/stop first", repeat_->route().back(),
                     private_node_.getNamespace());
}

std::string VmapNode::ClaimForStart() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) return "the node is stopping";
  if (mode_ != Mode::kIdle) return Busy();
  mode_ = Mode::kStarting;
  return "";
}

void VmapNode::ReleaseClaim() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (mode_ == Mode::kStarting) mode_ = Mode::kIdle;
}

std::string VmapNode::MapOf(const std::string& requested) const {
  if (!requested.empty()) return requested;
  std::string map;
  private_node_.getParam("map", map);
  return map;
}

void VmapNode::LogMessageError(const std::string& text, const std::string& problem) {
  std::lock_guard<std::mutex> lock(log_mutex_);
  const ros::WallTime now = ros::WallTime::now();
  if (problem == last_problem_ && (now - last_problem_time_).toSec() < kRepeatedErrorSeconds) return;
  last_problem_ = problem;
  last_problem_time_ = now;
  ROS_ERROR("%s", text.c_str());
}

void VmapNode::StopIfCameraQuiet() {
  double quiet = 0.0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ != Mode::kRepeating || quiet_stopped_ || camera_timeout_ <= 0.0) return;
    quiet = (ros::WallTime::now() - last_frame_).toSec();
    if (quiet < camera_timeout_) return;
  }
  std::lock_guard<std::mutex> run_lock(run_mutex_);  // no frame's command after this stop
  StopBetweenFrames();
  quiet_stopped_ = true;
  ROS_WARN("no camera frame on %s for %.1f s (~camera_timeout): the robot is stopped until frames come again",
           image_topic_.c_str(), quiet);
}

void VmapNode::Work() {
  while (!stopping_) {
    std::optional<Arrival> arrival = mailbox_.Take(kWorkerPoll);
    if (!arrival) {
      StopIfCameraQuiet();
      continue;
    }
    std::lock_guard<std::mutex> run_lock(run_mutex_);
    try {
      if (repeat_) RepeatFrame(*arrival);
    } catch (const std::exception& error) {
      // Not one error of a frame ends the node: the next frame is another chance. Meanwhile the robot stops, and
      // the same error is logged once in a while, not for every frame.
      LogMessageError(std::string("frame skipped: ") + error.what(), error.what());
      bool repeating = false;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        repeating = mode_ == Mode::kRepeating;
      }
      if (repeating) StopBetweenFrames();
    }
  }
}

}  // namespace vmap::ros_node
