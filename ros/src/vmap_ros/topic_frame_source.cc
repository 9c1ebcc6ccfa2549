#include "vmap_ros/topic_frame_source.h"

#include <fmt/format.h>
#include <ros/time.h>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/dataset_camera.h"
#include "vmap/sources/image_frame.h"

#include "vmap_ros/camera_messages.h"

namespace vmap::ros_node {
namespace {
constexpr std::chrono::milliseconds kPoll{100};
}  // namespace

TopicFrameSource::TopicFrameSource(std::string topic, const FrameSourceOptions& options, size_t capacity)
    : topic_(std::move(topic)), options_(options), mailbox_(capacity) {
  options_.Check();
  info_.path = topic_;
  info_.format = SourceFormat::kRecording;
  // --camera overrides the topic's CameraInfo, --camera none ignores it (as for a recording).
  if (!options_.camera.empty()) {
    camera_given_ = true;
    if (options_.camera != "none") camera_ = ParseCameraOption(options_.camera);
    camera_changed_ = camera_.has_value();
  }
}

void TopicFrameSource::Put(const topic_tools::ShapeShifter::ConstPtr& message) {
  double now = ros::Time::now().toSec();
  // ROS time reads 0 with /use_sim_time set and no /clock: frames without stamps would all be stamped 0.
  if (now <= 0.0) {
    now = ros::WallTime::now().toSec();
    if (!clock_warned_.exchange(true)) {
      spdlog::warn(
          "the ROS clock reads 0 (/use_sim_time is set and nothing publishes /clock?): {}'s frames without a "
          "stamp are stamped by the wall clock",
          topic_);
    }
  }
  if (mailbox_.Put(Received{message, now})) ++received_;
}

void TopicFrameSource::SetCamera(const std::optional<Camera>& camera) {
  std::lock_guard<std::mutex> lock(camera_mutex_);
  if (camera_given_) return;
  camera_given_ = true;
  camera_ = camera;
  camera_changed_ = true;
}

void TopicFrameSource::SetFallbackCamera(const std::optional<Camera>& camera) {
  std::lock_guard<std::mutex> lock(camera_mutex_);
  if (camera_given_) return;
  camera_ = camera;
  camera_changed_ = true;
}

void TopicFrameSource::End() { mailbox_.Close(); }

void TopicFrameSource::Skip(const std::string& why) {
  ++skipped_;
  const auto now = std::chrono::steady_clock::now();
  if (last_skip_warning_ && now - *last_skip_warning_ < std::chrono::duration<double>(kSkipWarningSeconds)) return;
  last_skip_warning_ = now;
  spdlog::warn("{}; skipping it ({} frame{} skipped so far)", why, skipped_, skipped_ == 1 ? "" : "s");
}

std::optional<Frame> TopicFrameSource::Next() {
  pulled_ = true;
  for (;;) {
    if (options_.last >= 0 && position_ > options_.last) return std::nullopt;
    std::optional<Received> received = mailbox_.Take(kPoll);
    if (!received) {
      if (mailbox_.closed_and_empty()) return std::nullopt;
      continue;
    }
    const long index = position_++;
    if (index < options_.first || (index - options_.first) % options_.stride != 0) continue;
    CameraImage image;
    try {
      image = DecodeCameraImage(*received->message, topic_);
    } catch (const InputError& error) {
      Skip(error.what());
      continue;
    }
    const std::string size_problem = FrameSizeProblem(image.gray.size(), options_);
    if (!size_problem.empty()) {
      Skip(fmt::format("{}: frame {} is {}x{}, {}", topic_, index, image.gray.cols, image.gray.rows, size_problem));
      continue;
    }
    Frame frame;
    frame.gray = std::move(image.gray);
    frame.color = std::move(image.color);
    frame.index = delivered_++;
    frame.source_index = static_cast<int>(index);
    frame.source_name = fmt::format("frame_{:06d}", index);
    frame.timestamp = image.stamp > 0.0 ? image.stamp : received->arrival;
    // Taken as they come: a live map cannot wait for late frames. `vmap build` on a bag of them orders a few at a time
    // by stamp, and makes another map; said once.
    if (frame.timestamp < last_stamp_ && !out_of_order_warned_) {
      out_of_order_warned_ = true;
      spdlog::warn(
          "{}: frame {} is stamped {:.6f} s, before the frame before it ({:.6f} s): frames are taken in the order "
          "they arrive (vmap build on a bag of them orders them by stamp, and its map may differ)",
          topic_, index, frame.timestamp, last_stamp_);
    }
    last_stamp_ = frame.timestamp;
    FitFrameToSequence(frame, &info_, options_, &size_warnings_);
    if (std::lock_guard<std::mutex> lock(camera_mutex_); camera_changed_) {
      // The map's camera is the source's when the map is written: a CameraInfo of the run replaces a fallback taken
      // on the frames before it.
      camera_changed_ = false;
      info_.camera.reset();
      if (camera_) {
        try {
          info_.camera = CameraForFrames(*camera_, info_.native_size, info_.frame_size);
        } catch (const InputError& error) {
          // A live run goes on without it (`vmap build` on a recording stops): the map has pixel headings only.
          spdlog::warn("{}; the map gets no camera (give ~camera to set one)", error.what());
          camera_.reset();
        }
      }
    }
    return frame;
  }
}

}  // namespace vmap::ros_node
