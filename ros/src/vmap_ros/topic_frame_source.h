#pragma once
// A camera topic as a frame source, for a teach run: the build pipeline pulls frames from it as from a recording
// (RunBuildPipeline with a source of the host's), while ROS's callbacks put the camera's messages in. Each message
// becomes a frame as `vmap build` makes one of the same message in a bag (the same decoder, sizes, stamps,
// numbering): a bag played to the node gives the map `vmap build` gives on the bag.

#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <string>

#include <topic_tools/shape_shifter.h>

#include "vmap/sources/frame_source.h"

#include "vmap_ros/mailbox.h"

namespace vmap::ros_node {

class TopicFrameSource final : public FrameSource {
 public:
  // `topic`: the image topic (recorded as the input's path, format "recording"). `options`: --resize, --strict,
  // --camera and the frame limits as `vmap build` takes them (format, first, last, stride, topic are the caller's to
  // refuse). `capacity`: messages held while the build is busy; beyond it the oldest are dropped, and counted.
  TopicFrameSource(std::string topic, const FrameSourceOptions& options, size_t capacity);

  // ROS's side. A camera message (never waits).
  void Put(const topic_tools::ShapeShifter::ConstPtr& message);
  // The camera of the topic's CameraInfo (nullopt: uncalibrated), unless the options give one; the first one since
  // the source was made wins, as `vmap build` takes a bag's first CameraInfo.
  void SetCamera(const std::optional<Camera>& camera);
  // A camera from before the run (the topic's last CameraInfo): taken until a CameraInfo of the run replaces it.
  void SetFallbackCamera(const std::optional<Camera>& camera);
  // The options refuse the topic's camera (--camera none).
  bool camera_refused() const { return options_.camera == "none"; }
  // Ends the input: Next() returns the messages already received, then nullopt.
  void End();

  // The build's side.
  std::optional<Frame> Next() override;
  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return skipped_; }

  // The build asked for a frame: it is set up (options checked, output claimed, matcher created).
  bool pulled() const { return pulled_; }
  long received() const { return received_; }          // messages put in
  size_t dropped() { return mailbox_.TakeDropped(); }  // messages pushed out of the mailbox since the last call

 private:
  struct Received {
    topic_tools::ShapeShifter::ConstPtr message;
    double arrival = 0.0;  // ROS time (s) it was put in: the frame's time when the camera sets no stamp
  };

  std::string topic_;
  FrameSourceOptions options_;
  Mailbox<Received> mailbox_;
  std::atomic<long> received_{0};
  std::atomic<bool> pulled_{false};

  std::mutex camera_mutex_;
  bool camera_given_ = false;  // by the options (--camera), or a CameraInfo already taken
  std::optional<Camera> camera_;
  bool camera_changed_ = false;  // camera_ is not yet the frames' (Next)

  SequenceInfo info_;  // written by Next() alone
  long position_ = 0;  // messages taken from the mailbox, malformed ones included
  int delivered_ = 0;
  int skipped_ = 0;
  int size_warnings_ = 0;
  double last_stamp_ = -1.0;          // of the frame before (Next)
  bool out_of_order_warned_ = false;  // Next
  std::atomic<bool> clock_warned_{false};
  // Skipped frames are said at most once every kSkipWarningSeconds (docs/ros.md), with the count so far: a camera
  // sending nothing but broken frames wrote a warning a frame.
  static constexpr double kSkipWarningSeconds = 5.0;
  std::optional<std::chrono::steady_clock::time_point> last_skip_warning_;
  void Skip(const std::string& why);
};

}  // namespace vmap::ros_node
