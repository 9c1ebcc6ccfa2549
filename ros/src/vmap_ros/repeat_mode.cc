// The node's repeat run (vmap_node.h): services, each camera frame localized, what is published for it.

#include <cmath>

#include <cv_bridge/cv_bridge.h>
#include <fmt/format.h>
#include <geometry_msgs/Twist.h>
#include <std_msgs/Bool.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "vmap/core/error.h"
#include "vmap/sources/odometry.h"

#include "vmap_ros/Localization.h"
#include "vmap_ros/debug_image.h"
#include "vmap_ros/localization_message.h"
#include "vmap_ros/parameter_reader.h"
#include "vmap_ros/service_answers.h"
#include "vmap_ros/vmap_node.h"

namespace vmap::ros_node {
namespace {

// The default of ~camera_timeout: a robot at 0.3 m/s drives 30 cm on its last command before it stops.
constexpr double kCameraTimeout = 1.0;

std::string RouteText(const std::vector<int>& route) {
  if (route.empty()) return "an empty route";
  return fmt::format("key image {} to {} ({} key images)", route.front(), route.back(), route.size());
}

}  // namespace

double VmapNode::ReadSeconds(const char* name, double unset, const char* meaning) const {
  XmlRpc::XmlRpcValue value;
  if (!private_node_.getParam(name, value)) return unset;
  // Read as a value first: getParam into a double leaves the default for "x", silently.
  double seconds = -1.0;
  if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble) seconds = static_cast<double>(value);
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) seconds = static_cast<int>(value);
  if (!(seconds >= 0.0 && seconds <= 3600.0)) {
    throw InputError(fmt::format("~{} must be a number of seconds in [0, 3600]: {}", name, meaning));
  }
  return seconds;
}

bool VmapNode::StartRepeat(vmap_ros::StartRepeat::Request& request, vmap_ros::StartRepeat::Response& response) {
  if (const std::string busy = ClaimForStart(); !busy.empty()) return Fail(response, "repeat/start: " + busy);
  StartClaim claim(this);  // until the run is set: a start that fails gives the node back idle
  const std::lock_guard<std::mutex> transition(transitions_mutex_);
  if (request.start < -1 || request.goal < -1) {
    return Fail(response, fmt::format("repeat/start: start {} and goal {}: each is a key image of the map, or -1 "
                                      "(the map's first, its last)",
                                      request.start, request.goal));
  }
  LocalizePipelineOptions options;
  options.map = MapOf(request.map);
  if (options.map.empty()) return Fail(response, "repeat/start: no map; give one in the request or set ~map");
  WarnAboutUnknownParameters(private_node_, KnownParameters());  // set since the node started, too
  ParameterReader parameters(private_node_);
  std::unique_ptr<RepeatRun> run;
  std::string taught_with;
  double camera_timeout = 0.0, odom_wait = 0.0;
  try {
    RefuseRecordingParameters();
    parameters.Read(options.session);  // vmap localize's flags, --from and --to included
    options.session.CheckGiven({parameters.given().begin(), parameters.given().end()});
    if (request.start >= 0) options.session.from = request.start;
    if (request.goal >= 0) options.session.to = request.goal;
    options.session.run.show_progress = false;
    ControllerOptions controller;
    parameters.Read(controller);  // the controller's flags (vmap simulate's)
    camera_timeout = ReadSeconds("camera_timeout", kCameraTimeout,
                                 "how long the robot keeps its last command without a camera frame (0: for ever)");
    odom_wait = ReadSeconds("odom_wait", 0.0, "how long a frame waits for the odometry of its time (0: not at all)");
    // The teach run's odometry (~teach_odometry, read with the session's options; else the map folder's), when the
    // robot had one, for the taught speeds and turns and the localizer's pace.
    run = std::make_unique<RepeatRun>(options, controller);
    const size_t taught = run->teach_odometry().size();
    taught_with =
        taught == 0 ? "the map alone (no teach odometry)" : fmt::format("the teach odometry ({} samples)", taught);
  } catch (const InputError& error) {
    // The request's start and goal set the session's from and to: an error of either names the request's field.
    if (const auto* option = dynamic_cast<const OptionError*>(&error)) {
      if (option->path() == "to" && request.goal >= 0) return Fail(response, "repeat/start: goal " + option->problem());
      if (option->path() == "from" && request.start >= 0) {
        return Fail(response, "repeat/start: start " + option->problem());
      }
    }
    return Fail(response, "repeat/start: " + parameters.Message(error));
  } catch (const std::exception& error) {
    return Fail(response, std::string("repeat/start: ") + error.what());
  }
  if (const std::vector<std::string> unread = TeachParametersSet(); !unread.empty()) {
    ROS_WARN(
        "repeat/start: %s %s teach runs' (the map's frame size, camera, mask and matcher come from the map); a "
        "repeat run does not read %s",
        fmt::format("{}", fmt::join(unread, ", ")).c_str(), unread.size() == 1 ? "is" : "are",
        unread.size() == 1 ? "it" : "them");
  }
  response.route = run->route();
  const std::optional<Camera> map_camera = run->options().camera;
  const std::string started = fmt::format("repeat run started on map {}: {}, the taught profile from {}", options.map,
                                          RouteText(run->route()), taught_with);
  {
    std::lock_guard<std::mutex> run_lock(run_mutex_);
    std::lock_guard<std::mutex> lock(mutex_);
    repeat_ = std::move(run);
    mode_ = Mode::kRepeating;
    claim.Keep();
    localized_once_ = false;
    goal_reached_ = false;
    camera_timeout_ = camera_timeout;
    odom_wait_ = odom_wait;
    last_frame_ = ros::WallTime::now();
    quiet_stopped_ = false;
    mailbox_.Reset(1);
  }
  odometry_.Clear();
  odometry_subscriber_ = node_.subscribe("odom", 50, &VmapNode::OnOdometry, this);
  {
    std::lock_guard<std::mutex> lock(camera_mutex_);
    map_camera_ = map_camera;
    camera_checked_ = false;
  }
  std_msgs::Bool localized;
  localized.data = false;
  localized_.publish(localized);
  SubscribeCamera();
  return Succeed(response, started);
}

bool VmapNode::PauseRepeat(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  // The frame in progress ends first, or its command would reach the robot after the stop below.
  std::lock_guard<std::mutex> run_lock(run_mutex_);
  std::lock_guard<std::mutex> lock(mutex_);
  if (mode_ == Mode::kPaused) return Fail(response, "repeat/pause: the repeat run is paused already");
  if (mode_ != Mode::kRepeating) return Fail(response, "repeat/pause: no repeat run is in progress");
  mode_ = Mode::kPaused;
  PublishStop();
  return Succeed(response, "repeat run paused: the robot stops; frames are still localized");
}

bool VmapNode::ResumeRepeat(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  std::lock_guard<std::mutex> run_lock(run_mutex_);  // the controller starts again between two frames
  std::lock_guard<std::mutex> lock(mutex_);
  if (mode_ != Mode::kRepeating && mode_ != Mode::kPaused) {
    return Fail(response, "repeat/resume: no repeat run is in progress");
  }
  if (mode_ == Mode::kRepeating) return Fail(response, "repeat/resume: the repeat run is not paused");
  repeat_->ResetController();
  mode_ = Mode::kRepeating;
  return Succeed(response, "repeat run resumed: the robot drives again once a frame is localized");
}

bool VmapNode::StopRepeat(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  const std::lock_guard<std::mutex> transition(transitions_mutex_);
  int frames = 0;
  {
    std::lock_guard<std::mutex> run_lock(run_mutex_);  // the frame in progress ends first
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ != Mode::kRepeating && mode_ != Mode::kPaused) {
      return Fail(response, "repeat/stop: no repeat run is in progress");
    }
    frames = repeat_->frames();
    mode_ = Mode::kIdle;
    repeat_.reset();
    mailbox_.Reset(1);
  }
  UnsubscribeCamera();
  odometry_subscriber_.shutdown();
  PublishStop();
  // Latched: a subscriber that comes later must not read a run that is over as localized.
  std_msgs::Bool localized;
  localized.data = false;
  localized_.publish(localized);
  return Succeed(response, fmt::format("repeat run stopped after {} frames", frames));
}

void VmapNode::OnOdometry(const nav_msgs::Odometry::ConstPtr& odometry) {
  // Both runs: a repeat run's controller reads it at each frame's time, a teach run keeps it for its map.
  const geometry_msgs::Quaternion& q = odometry->pose.pose.orientation;
  OdometrySample sample;
  sample.timestamp = odometry->header.stamp.toSec();
  sample.x = odometry->pose.pose.position.x;
  sample.y = odometry->pose.pose.position.y;
  sample.yaw = std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
  if (std::isfinite(sample.timestamp) && std::isfinite(sample.x) && std::isfinite(sample.y) &&
      std::isfinite(sample.yaw)) {
    if (odometry_.Add(sample)) {
      ROS_WARN_THROTTLE(5.0,
                        "the odometry on %s went back in time by more than %g s (a bag played in a loop? a clock "
                        "reset?): read anew from this message",
                        node_.resolveName("odom").c_str(), OdometryBuffer::kRestartSeconds);
    }
    std::lock_guard<std::mutex> lock(teach_odometry_mutex_);
    if (recording_teach_odometry_) {
      if (teach_odometry_.empty() || sample.timestamp > teach_odometry_.back().timestamp) {
        teach_odometry_.push_back(sample);
      } else {
        // The map's odometry is one path in time order: a sample from before the last one kept cannot join it.
        ROS_WARN_THROTTLE(5.0,
                          "an Odometry message on %s is stamped %.3f s, not after the last kept (%.3f s): the teach "
                          "run's odometry keeps its path in time order and leaves it out (a bag played in a loop?)",
                          node_.resolveName("odom").c_str(), sample.timestamp, teach_odometry_.back().timestamp);
      }
    }
  } else {
    LogMessageError("an Odometry message on " + node_.resolveName("odom") +
                        " has a value that is not a finite "
                        "number; the message is ignored",
                    "odometry not finite");
  }
}

void VmapNode::PublishStop() { PublishCommand(geometry_msgs::Twist()); }

void VmapNode::StopBetweenFrames() {
  if (repeat_) repeat_->ControllerStopped();
  PublishStop();
}

void VmapNode::PublishCommand(const geometry_msgs::Twist& command) {
  std::lock_guard<std::mutex> lock(command_mutex_);
  cmd_vel_.publish(halted_ ? geometry_msgs::Twist() : command);
}

void VmapNode::HaltRobot() {
  bool repeating = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    repeating = mode_ == Mode::kRepeating || mode_ == Mode::kPaused;
  }
  std::lock_guard<std::mutex> lock(command_mutex_);
  halted_ = true;
  if (repeating) cmd_vel_.publish(geometry_msgs::Twist());
}

void VmapNode::RepeatFrame(const Arrival& arrival) {
  Mode mode;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    mode = mode_;
  }
  if (mode == Mode::kIdle) return;
  last_frame_ = ros::WallTime::now();
  quiet_stopped_ = false;
  CameraImage image;
  try {
    image = DecodeCameraImage(*arrival.message, image_topic_);
  } catch (const InputError& error) {
    ++malformed_;
    LogMessageError(fmt::format("{}; frame skipped ({} so far)", error.what(), malformed_), error.what());
    // Not steered by what cannot be seen: the base would otherwise keep the last command for as long as the
    // camera sends frames that are no images.
    if (mode == Mode::kRepeating) StopBetweenFrames();
    return;
  }
  // The controller's clock is the camera's (an odometry topic stamps by the same clock); the arrival time for a
  // camera that leaves its stamps zero.
  const double time = image.stamp > 0.0 ? image.stamp : ros::Time::now().toSec();
  RepeatStep step;
  ControlSummary control;
  odometry_.WaitFor(time, odom_wait_);
  const std::optional<OdometrySample> odometry = odometry_.At(time);
  if (mode == Mode::kPaused) {
    step.localization = repeat_->Localize(image, odometry ? &*odometry : nullptr);
    control.state = "paused";
  } else {
    step = repeat_->Step(image, time, arrival.time.toSec(), odometry ? &*odometry : nullptr);
    control.state = ControllerStateName(step.control.state);
    control.steering = step.control.steering;
    control.command.linear.x = step.control.command.linear;
    control.command.angular.z = step.control.command.angular;
    PublishCommand(control.command);
    if (step.control.localized && !localized_once_) {
      localized_once_ = true;
      std_msgs::Bool message;
      message.data = true;
      localized_.publish(message);
      ROS_INFO("first localization: key image %d (%s)", step.localization.key,
               LocalizationStatusName(step.localization.status).c_str());
    }
    if (step.control.state == ControllerState::kReachedGoal && !goal_reached_) {
      goal_reached_ = true;
      ROS_INFO("goal key image %d reached: the robot stops", repeat_->route().back());
    }
  }
  control.localized = localized_once_;
  const LocalizationResult& result = step.localization;

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
