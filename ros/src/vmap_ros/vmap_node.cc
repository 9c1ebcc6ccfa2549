#include "vmap_ros/vmap_node.h"

#include <cv_bridge/cv_bridge.h>
#include <fmt/format.h>
#include <geometry_msgs/Twist.h>
#include <std_msgs/Bool.h>

#include "vmap/core/error.h"
#include "vmap/sources/recording_source.h"

#include "vmap_ros/Localization.h"
#include "vmap_ros/debug_image.h"
#include "vmap_ros/localization_message.h"
#include "vmap_ros/parameter_reader.h"

namespace vmap::ros_node {
namespace {

// The mailbox decides what is kept; ROS's own queue only holds messages while no spinner thread is free, and would
// drop them uncounted if it filled up.
constexpr uint32_t kImageQueue = 100;
constexpr std::chrono::milliseconds kWorkerPoll{100};
// A camera that keeps sending one malformed message is logged once every this many seconds.
constexpr double kRepeatedErrorSeconds = 5.0;

template <typename Response>
bool Fail(Response& response, const std::string& message) {
  ROS_ERROR("%s", message.c_str());
  response.success = false;
  response.message = message;
  return true;  // the call itself succeeded: the answer says why nothing was done
}

template <typename Response>
bool Succeed(Response& response, const std::string& message) {
  ROS_INFO("%s", message.c_str());
  response.success = true;
  response.message = message;
  return true;
}

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

std::string RouteText(const std::vector<int>& route) {
  if (route.empty()) return "an empty route";
  return fmt::format("key image {} to {} ({} key images)", route.front(), route.back(), route.size());
}

}  // namespace

VmapNode::VmapNode(const ros::NodeHandle& node, const ros::NodeHandle& private_node)
    : node_(node), private_node_(private_node) {
  image_topic_ = node_.resolveName("image");
  // camera_info beside the image topic, as image_transport pairs them, unless it is remapped itself.
  const std::string remapped = node_.resolveName("camera_info");
  camera_info_topic_ =
      remapped != node_.resolveName("camera_info", false) ? remapped : CameraInfoTopicFor(image_topic_);

  cmd_vel_ = node_.advertise<geometry_msgs::Twist>("cmd_vel", 1);
  localization_ = private_node_.advertise<vmap_ros::Localization>("localization", 10);
  localized_ = private_node_.advertise<std_msgs::Bool>("localized", 1, /*latch=*/true);
  debug_image_ = private_node_.advertise<sensor_msgs::Image>("debug_image", 1);
  services_.push_back(private_node_.advertiseService("repeat/start", &VmapNode::StartRepeat, this));
  services_.push_back(private_node_.advertiseService("repeat/pause", &VmapNode::PauseRepeat, this));
  services_.push_back(private_node_.advertiseService("repeat/resume", &VmapNode::ResumeRepeat, this));
  services_.push_back(private_node_.advertiseService("repeat/stop", &VmapNode::StopRepeat, this));

  // Every option the node reads, to tell a typo from a parameter.
  ParameterReader known(private_node_);
  LocalizerOptions localizer;
  known.Read(localizer);
  std::set<std::string> names = known.known();
  names.insert({"map", "no_cache"});
  WarnAboutUnknownParameters(private_node_, names);

  worker_ = std::thread([this] { Work(); });
  ROS_INFO("vmap node ready: camera %s (%s); call %s/repeat/start", image_topic_.c_str(), camera_info_topic_.c_str(),
           private_node_.getNamespace().c_str());
}

VmapNode::~VmapNode() {
  stopping_ = true;
  mailbox_.Close();
  if (worker_.joinable()) worker_.join();
}

void VmapNode::OnImage(const topic_tools::ShapeShifter::ConstPtr& message) {
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
  std::lock_guard<std::mutex> lock(camera_mutex_);
  camera_ = camera;
  if (camera_checked_ || !camera || !map_camera_) return;
  camera_checked_ = true;
  const std::string problem = CameraMismatch(*camera, *map_camera_);
  if (!problem.empty()) ROS_WARN("%s", problem.c_str());
}

std::string VmapNode::MapOf(const std::string& requested) const {
  if (!requested.empty()) return requested;
  std::string map;
  private_node_.getParam("map", map);
  return map;
}

bool VmapNode::StartRepeat(vmap_ros::StartRepeat::Request& request, vmap_ros::StartRepeat::Response& response) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ != Mode::kIdle) {
      return Fail(response, fmt::format("a repeat run is in progress (goal {}); call {}/repeat/stop first",
                                        repeat_->route().back(), private_node_.getNamespace()));
    }
  }
  RepeatRequest repeat;
  repeat.map = MapOf(request.map);
  repeat.goal = request.goal;
  repeat.start = request.start;
  if (repeat.map.empty()) return Fail(response, "repeat/start: no map; give one in the request or set ~map");
  ParameterReader parameters(private_node_);
  std::unique_ptr<RepeatRun> run;
  try {
    parameters.Read(repeat.localizer);
    bool no_cache = false;
    private_node_.getParam("no_cache", no_cache);
    repeat.cache = !no_cache;
    run = std::make_unique<RepeatRun>(repeat);
  } catch (const InputError& error) {
    return Fail(response, "repeat/start: " + parameters.Message(error));
  } catch (const std::exception& error) {
    return Fail(response, std::string("repeat/start: ") + error.what());
  }
  response.route = run->route();
  const std::optional<Camera> map_camera = run->options().camera;
  const std::string started =
      fmt::format("repeat run started on map {}: {}", repeat.map.string(), RouteText(run->route()));
  {
    std::lock_guard<std::mutex> run_lock(run_mutex_);
    std::lock_guard<std::mutex> lock(mutex_);
    repeat_ = std::move(run);
    mode_ = Mode::kRepeating;
    localized_once_ = false;
    mailbox_.Reset(1);
  }
  {
    std::lock_guard<std::mutex> lock(camera_mutex_);
    map_camera_ = map_camera;
    camera_checked_ = false;
  }
  std_msgs::Bool localized;
  localized.data = false;
  localized_.publish(localized);
  image_subscriber_ =
      node_.subscribe(image_topic_, kImageQueue, &VmapNode::OnImage, this, ros::TransportHints().tcpNoDelay());
  camera_info_subscriber_ = node_.subscribe(camera_info_topic_, 1, &VmapNode::OnCameraInfo, this);
  return Succeed(response, started);
}

bool VmapNode::PauseRepeat(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (mode_ == Mode::kIdle) return Fail(response, "repeat/pause: no repeat run is in progress");
  if (mode_ == Mode::kPaused) return Fail(response, "repeat/pause: the repeat run is paused already");
  mode_ = Mode::kPaused;
  PublishStop();
  return Succeed(response, "repeat run paused: the robot stops; frames are still localized");
}

bool VmapNode::ResumeRepeat(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (mode_ == Mode::kIdle) return Fail(response, "repeat/resume: no repeat run is in progress");
  if (mode_ == Mode::kRepeating) return Fail(response, "repeat/resume: the repeat run is not paused");
  mode_ = Mode::kRepeating;
  return Succeed(response, "repeat run resumed");
}

bool VmapNode::StopRepeat(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  int frames = 0;
  {
    std::lock_guard<std::mutex> run_lock(run_mutex_);  // the frame in progress ends first
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ == Mode::kIdle) return Fail(response, "repeat/stop: no repeat run is in progress");
    frames = repeat_->frames();
    mode_ = Mode::kIdle;
    repeat_.reset();
    mailbox_.Reset(1);
  }
  image_subscriber_.shutdown();
  camera_info_subscriber_.shutdown();
  PublishStop();
  return Succeed(response, fmt::format("repeat run stopped after {} frames", frames));
}

void VmapNode::LogMessageError(const std::string& text, const std::string& problem) {
  std::lock_guard<std::mutex> lock(log_mutex_);
  const ros::WallTime now = ros::WallTime::now();
  if (problem == last_problem_ && (now - last_problem_time_).toSec() < kRepeatedErrorSeconds) return;
  last_problem_ = problem;
  last_problem_time_ = now;
  ROS_ERROR("%s", text.c_str());
}

void VmapNode::PublishStop() { cmd_vel_.publish(geometry_msgs::Twist()); }

void VmapNode::Work() {
  while (!stopping_) {
    std::optional<Arrival> arrival = mailbox_.Take(kWorkerPoll);
    if (!arrival) continue;
    std::lock_guard<std::mutex> run_lock(run_mutex_);
    try {
      if (repeat_) RepeatFrame(*arrival);
    } catch (const std::exception& error) {
      // Not one error of a frame ends the node: the next frame is another chance.
      ROS_ERROR("frame skipped: %s", error.what());
    }
  }
}

void VmapNode::RepeatFrame(const Arrival& arrival) {
  Mode mode;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    mode = mode_;
  }
  if (mode == Mode::kIdle) return;
  CameraImage image;
  try {
    image = DecodeCameraImage(*arrival.message, image_topic_);
  } catch (const InputError& error) {
    ++malformed_;
    LogMessageError(fmt::format("{}; frame skipped ({} so far)", error.what(), malformed_), error.what());
    return;
  }
  const LocalizationResult result = repeat_->Localize(image);
  const bool localized =
      result.status == LocalizationStatus::kTracking || result.status == LocalizationStatus::kRelocalized;
  ControlSummary control;
  if (localized && !localized_once_) {
    localized_once_ = true;
    std_msgs::Bool message;
    message.data = true;
    localized_.publish(message);
    ROS_INFO("first localization: key image %d (%s)", result.key, LocalizationStatusName(result.status).c_str());
  }
  control.localized = localized_once_;
  if (mode == Mode::kPaused) control.state = "paused";

  vmap_ros::Localization message = LocalizationMessage(image.header, result, repeat_->route(), control);
  message.latency = (ros::WallTime::now() - arrival.time).toSec();
  message.frames_dropped = static_cast<uint32_t>(mailbox_.TakeDropped());
  localization_.publish(message);

  if (debug_image_.getNumSubscribers() > 0) {
    const KeyComparison* comparison = SteeringComparison(result);
    const std::string caption =
        fmt::format("frame {} {} | key {} next {} | {}", result.frame_index, LocalizationStatusName(result.status),
                    result.key, result.next_key, control.state);
    const cv::Mat figure =
        DrawDebugImage(repeat_->frame().color.empty() ? repeat_->frame().gray : repeat_->frame().color,
                       comparison ? repeat_->KeyImage(comparison->key) : cv::Mat(), comparison, caption);
    debug_image_.publish(cv_bridge::CvImage(image.header, "bgr8", figure).toImageMsg());
  }
}

}  // namespace vmap::ros_node
