// The node's teach run (vmap_node.h): services, the camera's frames into the build pipeline, progress.

#include <filesystem>
#include <mutex>
#include <vector>

#include <fmt/format.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "vmap/core/error.h"
#include "vmap/pipelines/localize_odometry.h"

#include "vmap_ros/TeachProgress.h"
#include "vmap_ros/parameter_reader.h"
#include "vmap_ros/service_answers.h"
#include "vmap_ros/vmap_node.h"

namespace vmap::ros_node {
namespace {

// Frames held while the map builder is busy, by default: two seconds of a 30 Hz camera.
constexpr int kTeachQueue = 60;

}  // namespace

bool VmapNode::StartTeach(vmap_ros::StartTeach::Request& request, vmap_ros::StartTeach::Response& response) {
  if (const std::string busy = ClaimForStart(); !busy.empty()) return Fail(response, "teach/start: " + busy);
  StartClaim claim(this);  // until the run is set: a start that fails gives the node back idle
  const std::lock_guard<std::mutex> transition(transitions_mutex_);
  const std::string map = MapOf(request.map);
  if (map.empty()) return Fail(response, "teach/start: no map; give one in the request or set ~map");
  WarnAboutUnknownParameters(private_node_, KnownParameters());  // set since the node started, too
  ParameterReader parameters(private_node_);
  std::unique_ptr<TeachRun> run;
  try {
    BuildPipelineOptions options;
    parameters.Read(options);
    RefuseRecordingParameters();
    options.input = image_topic_;
    options.output = map;
    options.until_interrupted = false;
    options.map.show_progress = false;
    options.map.after_frame = [this] { PublishTeachProgress(); };
    // The odometry so far rides with every snapshot, so that a node killed between them (SIGKILL, power) leaves a
    // map and the odometry of the same stretch.
    options.write_beside_map = [this](const std::filesystem::path& folder) {
      std::vector<OdometrySample> odometry;
      {
        std::lock_guard<std::mutex> lock(teach_odometry_mutex_);
        odometry = teach_odometry_;
      }
      if (!odometry.empty()) WriteTeachOdometry(folder, odometry);
    };
    options.files_beside_map = {kTeachOdometryFileName};
    int capacity = kTeachQueue;
    if (XmlRpc::XmlRpcValue queue; private_node_.getParam("teach_queue", queue)) {
      // Read as a value first: getParam into an int leaves the default for "x" or 1.5, silently.
      if (queue.getType() != XmlRpc::XmlRpcValue::TypeInt || static_cast<int>(queue) < 1) {
        throw InputError("~teach_queue must be an integer of at least 1 (frames held while the builder is busy)");
      }
      capacity = static_cast<int>(queue);
    }
    run = std::make_unique<TeachRun>(options, static_cast<size_t>(capacity));
  } catch (const InputError& error) {
    return Fail(response, "teach/start: " + parameters.Message(error));
  } catch (const std::exception& error) {
    return Fail(response, std::string("teach/start: ") + error.what());
  }
  {
    std::lock_guard<std::mutex> camera_lock(camera_mutex_);
    // The latest CameraInfo, if the topic went quiet before: one of this run replaces it (the camera may have changed).
    if (camera_) run->source().SetFallbackCamera(camera_);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    teach_ = std::move(run);
    teach_frames_ = 0;
    teach_dropped_ = 0;
    mode_ = Mode::kTeaching;
    claim.Keep();
  }
  {
    std::lock_guard<std::mutex> lock(teach_odometry_mutex_);
    teach_odometry_.clear();
    recording_teach_odometry_ = true;
  }
  SubscribeCamera();
  odometry_subscriber_ = node_.subscribe("odom", 100, &VmapNode::OnOdometry, this);
  return Succeed(response, fmt::format("teach run started: frames of {} go into the map {}", image_topic_, map));
}

bool VmapNode::StopTeach(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  {
    // Said at once, not after the map being written.
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ == Mode::kFinishing) {
      return Fail(response, "teach/stop: the teach run is stopping already; its map is being written");
    }
  }
  const std::lock_guard<std::mutex> transition(transitions_mutex_);
  std::unique_ptr<TeachRun> run;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (mode_ == Mode::kFinishing) {
      return Fail(response, "teach/stop: the teach run is stopping already; its map is being written");
    }
    if (mode_ != Mode::kTeaching) return Fail(response, "teach/stop: no teach run is in progress");
    run = std::move(teach_);
    mode_ = Mode::kFinishing;  // no other run starts while this map is written
  }
  UnsubscribeCamera();
  std::string answer;
  const bool written = FinishTeach(std::move(run), &answer);
  return written ? Succeed(response, answer) : Fail(response, "teach/stop: " + answer);
}

bool VmapNode::FinishTeach(std::unique_ptr<TeachRun> run, std::string* answer_text) {
  odometry_subscriber_.shutdown();
  {
    std::lock_guard<std::mutex> lock(teach_odometry_mutex_);
    recording_teach_odometry_ = false;  // the map, written by Stop, takes what came until here
  }
  const long received = run->source().received();
  std::string& answer = *answer_text;
  bool success = true;
  try {
    const BuildPipelineResult result = run->Stop();
    size_t odometry_samples = 0;
    {
      std::lock_guard<std::mutex> lock(teach_odometry_mutex_);
      odometry_samples = teach_odometry_.size();
      std::vector<OdometrySample>().swap(teach_odometry_);
    }
    teach_dropped_ += static_cast<long>(run->source().dropped());
    answer = fmt::format("teach run stopped: map {} written, {} key images from {} frames ({} dropped, {} skipped)",
                         result.directory.string(), result.map.key_images.size(), teach_frames_.load(),
                         teach_dropped_.load(), run->source().skipped_frames());
    if (odometry_samples > 0) {
      answer += fmt::format(", and {} odometry samples beside it ({})", odometry_samples, kTeachOdometryFileName);
    }
    if (!result.map.input.camera) {
      // Said here, not first at repeat/start ("~focal_px must be given"), when the teach run could still be redone.
      const std::string why = run->source().camera_refused()
                                  ? std::string("~camera is none")
                                  : fmt::format("no CameraInfo came on {} and ~camera was not set", camera_info_topic_);
      const std::string without = fmt::format(
          "; the map has no camera ({}): its headings are in pixels, and a repeat run on it needs ~focal_px", why);
      ROS_WARN("teach run: %s", without.substr(2).c_str());
      answer += without;
    }
  } catch (const std::exception& error) {
    success = false;
    if (received == 0) {
      // The pipeline's reason names the CLI's flags; the node's cause is its topic.
      answer = fmt::format(
          "no frame came on {} during the run, so there is no map to write (a map already there is kept); check "
          "that the camera publishes on it (rostopic hz {})",
          image_topic_, image_topic_);
    } else {
      answer = fmt::format("the map could not be written ({} frames received): {}", received, error.what());
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    mode_ = Mode::kIdle;
  }
  return success;
}

void VmapNode::PublishTeachProgress() {
  ++teach_frames_;
  vmap_ros::TeachProgress progress;
  progress.header.stamp = ros::Time::now();
  progress.frames = static_cast<uint32_t>(teach_frames_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (teach_) {
      teach_dropped_ += teach_->source().dropped();
      progress.skipped = static_cast<uint32_t>(teach_->source().skipped_frames());
    }
  }
  progress.dropped = static_cast<uint32_t>(teach_dropped_);
  teach_progress_.publish(progress);
}

}  // namespace vmap::ros_node
