#include "vmap_ros/simulator_node.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>

#include <fmt/format.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Bool.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"
#include "vmap/pipelines/simulate_pipeline.h"
#include "vmap/simulation/teach_run.h"
#include "vmap/simulation/trial_run.h"

#include "vmap_ros/Localization.h"
#include "vmap_ros/parameter_reader.h"
#include "vmap_ros/terminate_signal.h"

namespace vmap::ros_node {
namespace {

namespace fs = std::filesystem;

// The simulation's clock starts at 0; ROS reads a zero stamp as "no stamp", so the topics' stamps start here.
constexpr double kStampOffset = 1000.0;

// The node's own parameters, as fields: read, typed and range-checked as every option is (parameter_reader.h).
struct SimulatorNodeOptions {
  int trial = 0;
  double answer_timeout = 60.0;

  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Visit(OptionField{"trial", "--trial", "The index of `vmap simulate`'s trial to run"}.AtLeast(0), trial);
    visitor.Visit(
        OptionField{"answer_timeout", "--answer-timeout", "Seconds to wait for the vmap node's answer to a frame"}
            .Within(0.01, 86400)
            .Unit("s"),
        answer_timeout);
  }
  void Check() const { CheckFieldRanges(*this); }
};

struct SimulatorParameters {
  SimulatePipelineOptions pipeline;  // the simulation, the matcher, the map (~map) and the result (~result)
  SimulatorNodeOptions node;
};

// `reader` names the parameters in the errors of what it read, here and later (a texture folder's).
SimulatorParameters ReadParameters(const ros::NodeHandle& private_node, ParameterReader& reader) {
  SimulatorParameters parameters;
  SimulatePipelineOptions& pipeline = parameters.pipeline;
  try {
    // --map and --json are `vmap simulate`'s; the node's result is ~result.
    reader.Read(pipeline);
    reader.Read(parameters.node);
    parameters.node.Check();
    if (private_node.hasParam("json") || private_node.hasParam("report")) {
      throw InputError("~json and ~report are `vmap simulate`'s; the node writes its trial to ~result");
    }
    XmlRpc::XmlRpcValue result;
    if (private_node.getParam("result", result)) {
      if (result.getType() != XmlRpc::XmlRpcValue::TypeString) {
        throw InputError("~result must be a string: the JSON file the trial is written to");
      }
      pipeline.json = static_cast<std::string>(result);
    }
    pipeline.simulation.trials = 1;
    if (pipeline.map.empty()) throw InputError("~map must name a folder for the teach run's map (new or empty)");
    // Before the teach run: the map's folder, the result, and what they may not replace.
    try {
      CheckSimulateOutputs(pipeline);
    } catch (const OptionError& error) {
      if (error.path() == "json") throw InputError("~result " + error.problem());  // `vmap simulate --json`'s check
      throw;
    }
  } catch (const InputError& error) {
    throw InputError(reader.Message(error));
  }
  ParameterNames names;
  names.Add(pipeline);
  names.Add(parameters.node);
  std::set<std::string> known = names.names();
  known.insert("result");
  WarnAboutUnknownParameters(private_node, known);
  return parameters;
}

// Thrown from the teach run's frames when the node is asked to stop.
struct StopRequestedError : std::runtime_error {
  StopRequestedError() : std::runtime_error("stopped by a signal") {}
};

// The exit status of a node stopped by a signal, as a shell reports one (130 for SIGINT).
int StoppedStatus() { return StopSignal() != 0 ? 128 + StopSignal() : 1; }

// The vmap node's answer to the frame awaited: its localization message, stamped as the frame, which carries the
// command the node published for it on cmd_vel. Paired by stamp, not by counting cmd_vel messages: the node also
// publishes a stop between frames (a pause, a quiet camera, a malformed frame), after which every frame was driven by
// the command of the frame before it.
class Answers {
 public:
  void OnLocalization(const vmap_ros::Localization::ConstPtr& message) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (message->header.stamp != awaited_) return;
      answer_ = *message;
    }
    changed_.notify_all();
  }
  // The frame stamped `stamp` is about to be sent: an answer to it may come before Wait is called.
  void Await(const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    awaited_ = stamp;
    answer_.reset();
  }
  // Waits up to `seconds` for the answer to the frame awaited; calls `resend` every time `resend_wanted()` says so
  // while waiting (a vmap node restarted, whose new subscription never saw the frame).
  std::optional<vmap_ros::Localization> Wait(double seconds, const std::function<bool()>& resend_wanted,
                                             const std::function<void()>& resend) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    std::unique_lock<std::mutex> lock(mutex_);
    while (!answer_ && std::chrono::steady_clock::now() < deadline && !StopRequested()) {
      changed_.wait_for(lock, std::chrono::milliseconds(100), [&] { return answer_.has_value(); });
      if (!answer_ && resend_wanted()) {
        lock.unlock();
        resend();
        lock.lock();
      }
    }
    return answer_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  ros::Time awaited_;
  std::optional<vmap_ros::Localization> answer_;
};

sensor_msgs::Image ImageMessage(const Frame& frame, const ros::Time& stamp) {
  sensor_msgs::Image image;
  image.header.stamp = stamp;
  image.header.frame_id = "camera";
  image.height = frame.color.rows;
  image.width = frame.color.cols;
  image.encoding = "bgr8";
  image.step = static_cast<uint32_t>(frame.color.cols * 3);
  image.data.resize(image.step * image.height);
  for (int y = 0; y < frame.color.rows; ++y) {
    std::memcpy(&image.data[y * image.step], frame.color.ptr(y), image.step);
  }
  return image;
}

sensor_msgs::CameraInfo CameraInfoMessage(const Camera& camera, const ros::Time& stamp) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = stamp;
  info.header.frame_id = "camera";
  info.width = camera.size.width;
  info.height = camera.size.height;
  info.distortion_model = "plumb_bob";
  info.D = {0, 0, 0, 0, 0};
  info.K = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0};
  return info;
}

nav_msgs::Odometry OdometryMessage(const OdometrySample& odometry, const ros::Time& stamp) {
  nav_msgs::Odometry message;
  message.header.stamp = stamp;
  message.header.frame_id = "odom";
  message.child_frame_id = "base_link";
  message.pose.pose.position.x = odometry.x;
  message.pose.pose.position.y = odometry.y;
  message.pose.pose.orientation.z = std::sin(0.5 * odometry.yaw);
  message.pose.pose.orientation.w = std::cos(0.5 * odometry.yaw);
  return message;
}

// The localization and the controller's step a trial records, from the vmap node's messages.
void FromMessage(const vmap_ros::Localization& message, LocalizationResult* localization, ControlStep* step) {
  localization->key = message.key;
  localization->next_key = message.next_key;
  switch (message.status) {
    case vmap_ros::Localization::TRACKING:
      localization->status = LocalizationStatus::kTracking;
      break;
    case vmap_ros::Localization::RELOCALIZED:
      localization->status = LocalizationStatus::kRelocalized;
      break;
    case vmap_ros::Localization::UNCERTAIN:
      localization->status = LocalizationStatus::kUncertain;
      break;
    default:
      localization->status = LocalizationStatus::kLost;
  }
  step->state = FindEnum(kControllerStateNames, message.controller_state).value_or(ControllerState::kLost);
  step->steering = message.steering;
  step->localized = message.localized;
  step->target_key = message.next_key >= 0 ? message.next_key : message.key;
  step->command.linear = message.command.linear.x;
  step->command.angular = message.command.angular.z;
}

nlohmann::json TrialJson(const TrialResult& trial) {
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"end", trial.end},
          {"reached_goal", trial.reached_goal},
          {"success", trial.success},
          {"final_error", number(trial.final_error)},
          {"lateral_rms_second_half", number(trial.lateral_rms_second_half)},
          {"lateral_max", number(trial.lateral_max)},
          {"start_lateral", trial.start_lateral},
          {"start_heading_deg", trial.start_heading_deg},
          {"frames", trial.frames},
          {"frames_lost", trial.frames_lost},
          {"duration", trial.duration}};
}

int RunTheSimulator(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  SimulatorParameters parameters;
  std::unique_ptr<PreparedTrials> prepared;
  ParameterReader reader(private_node);
  try {
    parameters = ReadParameters(private_node, reader);
    const SimulatePipelineOptions& pipeline = parameters.pipeline;
    ROS_INFO("teaching route %s into %s", pipeline.simulation.route.c_str(), pipeline.map.c_str());
    prepared = PrepareTrials(pipeline.simulation, pipeline.matcher, pipeline.map, [] {
      if (StopRequested()) throw StopRequestedError();
    });
  } catch (const StopRequestedError&) {
    ROS_WARN("vmap simulator: stopped during the teach run; its map was not written");
    return StoppedStatus();
  } catch (const InputError& error) {  // named as the parameters name it (~teach_textures)
    ROS_ERROR("vmap simulator: %s", reader.Message(error).c_str());
    return 2;
  } catch (const std::exception& error) {
    ROS_ERROR("vmap simulator: %s", error.what());
    return 2;
  }
  const int trial = parameters.node.trial;
  const double answer_timeout = parameters.node.answer_timeout;
  const std::string& result_file = parameters.pipeline.json;
  const TrialContext& context = prepared->context;
  ROS_INFO("map written: %zu key images from %d frames; running trial %d in process for reference",
           prepared->map().map.key_images.size(), prepared->teach_frames, trial);
  const TrialResult in_process = RunTrial(context, trial);

  // The robot on ROS.
  // A subscriber that connects while a frame waits for its answer (a vmap node restarted) is sent the frame again.
  std::atomic<bool> camera_subscribed{false};
  ros::Publisher camera = node.advertise<sensor_msgs::Image>(
      "camera/image_raw", 1, [&](const ros::SingleSubscriberPublisher&) { camera_subscribed = true; });
  ros::Publisher camera_info = node.advertise<sensor_msgs::CameraInfo>("camera/camera_info", 1);
  ros::Publisher odometry = node.advertise<nav_msgs::Odometry>("odom", 10);
  ros::Publisher ready = private_node.advertise<std_msgs::Bool>("ready", 1, /*latch=*/true);
  Answers answers;
  // The commands travel in the localization messages too; subscribed to meet the vmap node's publisher (a remapping
  // that does not meet it is said while waiting).
  const ros::Subscriber commands = node.subscribe<geometry_msgs::Twist>(
      "cmd_vel", 100, boost::function<void(const geometry_msgs::Twist::ConstPtr&)>([](const auto&) {}));
  const ros::Subscriber localizations = node.subscribe("localization", 100, &Answers::OnLocalization, &answers);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  std_msgs::Bool map_ready;
  map_ready.data = true;
  ready.publish(map_ready);
  const auto waiting = [&] {
    return camera.getNumSubscribers() == 0 || localizations.getNumPublishers() == 0 || commands.getNumPublishers() == 0;
  };
  // Said again every 30 s: a remapped topic that does not meet the vmap node's would otherwise wait in silence.
  for (int seconds = 0; !StopRequested() && waiting(); seconds += 30) {
    ROS_INFO("waiting for a vmap node on %s, %s and %s (start its repeat run on %s)%s", camera.getTopic().c_str(),
             localizations.getTopic().c_str(), commands.getTopic().c_str(), parameters.pipeline.map.c_str(),
             seconds > 0 ? fmt::format(": {} s so far", seconds).c_str() : "");
    for (int i = 0; i < 3000 && !StopRequested() && waiting(); ++i) ros::WallDuration(0.01).sleep();
  }

  const Camera rig = RigCamera(parameters.pipeline.simulation.camera);
  TrialRun run(context, trial);
  std::string failure;
  while (!StopRequested() && run.Continues()) {
    const Frame frame = run.Render();
    const ros::Time stamp(kStampOffset + run.time());
    const auto send = [&] {
      camera_subscribed = false;
      odometry.publish(OdometryMessage(run.odometry(), stamp));
      camera_info.publish(CameraInfoMessage(rig, stamp));
      camera.publish(ImageMessage(frame, stamp));
    };
    answers.Await(stamp);
    send();
    const auto sent = std::chrono::steady_clock::now();
    const std::optional<vmap_ros::Localization> message = answers.Wait(
        answer_timeout, [&] { return camera_subscribed.load(); }, send);
    if (!message) {
      if (StopRequested()) break;
      failure = fmt::format("no answer from the vmap node to frame {} within {} s (~answer_timeout)", run.step(),
                            answer_timeout);
      break;
    }
    LocalizationResult localization;
    ControlStep step;
    FromMessage(*message, &localization, &step);
    run.Record(localization, step, std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count());
    // At the goal the controller slows the robot down within its decelerations: the robot stops where that ends.
    if (step.state == ControllerState::kReachedGoal && step.command.stops()) break;
    run.Drive(step.command);
  }
  if (StopRequested()) {
    ROS_WARN("vmap simulator: stopped during trial %d after %d frames; no result written", trial, run.step());
    return StoppedStatus();
  }
  TrialResult through_ros = run.Finish();
  if (!failure.empty() && through_ros.end.empty()) through_ros.end = "no answer";
  nlohmann::json result = {{"route", context.route->name},
                           {"trial", trial},
                           {"key_images", prepared->map().map.key_images.size()},
                           {"ros", TrialJson(through_ros)},
                           {"in_process", TrialJson(in_process)}};
  if (!failure.empty()) result["failure"] = failure;
  if (!result_file.empty()) {
    try {
      WriteFileAtomically(result_file, result.dump(2) + "\n");
    } catch (const std::exception& error) {
      ROS_ERROR("vmap simulator: the result could not be written: %s", error.what());
      return 2;
    }
  }
  ROS_INFO("trial %d through ROS: %s, %.3f m from the goal (in process: %s, %.3f m)", trial, through_ros.end.c_str(),
           through_ros.final_error, in_process.end.c_str(), in_process.final_error);
  if (!failure.empty()) {
    ROS_ERROR("vmap simulator: %s", failure.c_str());
    return 2;
  }
  return 0;
}

}  // namespace

int RunSimulatorNode(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  try {
    return RunTheSimulator(node, private_node);
  } catch (const StopRequestedError&) {  // from a trial's frames (the context's after_frame)
    ROS_WARN("vmap simulator: stopped during a trial; no result written");
    return StoppedStatus();
  }
}

}  // namespace vmap::ros_node
