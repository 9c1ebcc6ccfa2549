#pragma once
// The vmap node (docs/ros.md): repeat runs on a robot.
//
// Topics (remappable):      image (sensor_msgs/Image or CompressedImage), camera_info (beside image, as
//                           image_transport pairs them); publishes cmd_vel (geometry_msgs/Twist).
// Private topics:           ~localization (vmap_ros/Localization, one per frame processed), ~debug_image
//                           (sensor_msgs/Image, drawn only while someone subscribes; a plain publisher, since
//                           Debian's image_transport cannot be linked: it needs a ROS 1 pluginlib), ~localized
//                           (std_msgs/Bool, latched: true once a repeat run's first frame is localized).
// Services:                 ~repeat/start, ~repeat/pause, ~repeat/resume, ~repeat/stop.
// Parameters:               the flags of `vmap localize` by their names (parameter_reader.h), read when a run
//                           starts; ~map, the map directory.
//
// Threads: ROS's spinner threads run the callbacks and services; the camera callback only drops the message in a
// mailbox (mailbox.h), and one worker thread decodes, localizes and publishes. In a repeat run the mailbox holds
// one frame: the worker always takes the newest, so a slow frame delays no other (frames arriving meanwhile are
// dropped and counted in the next message's frames_dropped). No error of a message, a map or a service call ends
// the node: each is answered or logged, and the node goes on.

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <std_srvs/Trigger.h>
#include <topic_tools/shape_shifter.h>

#include "vmap_ros/StartRepeat.h"
#include "vmap_ros/mailbox.h"
#include "vmap_ros/repeat_run.h"

namespace vmap::ros_node {

class VmapNode {
 public:
  // `node`: the namespace of the topics (image, camera_info, odom, cmd_vel); `private_node`: "~".
  VmapNode(const ros::NodeHandle& node, const ros::NodeHandle& private_node);
  ~VmapNode();
  VmapNode(const VmapNode&) = delete;
  VmapNode& operator=(const VmapNode&) = delete;

 private:
  enum class Mode { kIdle, kRepeating, kPaused };
  struct Arrival {
    topic_tools::ShapeShifter::ConstPtr message;
    ros::WallTime time;  // when the callback got it
  };

  void OnImage(const topic_tools::ShapeShifter::ConstPtr& message);
  void OnCameraInfo(const sensor_msgs::CameraInfo::ConstPtr& info);

  bool StartRepeat(vmap_ros::StartRepeat::Request& request, vmap_ros::StartRepeat::Response& response);
  bool PauseRepeat(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool ResumeRepeat(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool StopRepeat(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);

  void Work();
  void RepeatFrame(const Arrival& arrival);
  void PublishStop();
  // Logs an error of a message: at once when its problem differs from the last one logged, else at most every
  // few seconds (a camera sending one malformed message 30 times a second would flood the log).
  void LogMessageError(const std::string& text, const std::string& problem);
  std::string MapOf(const std::string& requested) const;

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  std::string image_topic_;
  std::string camera_info_topic_;

  ros::Subscriber image_subscriber_;
  ros::Subscriber camera_info_subscriber_;
  ros::Publisher cmd_vel_;
  ros::Publisher localization_;
  ros::Publisher localized_;
  ros::Publisher debug_image_;
  std::vector<ros::ServiceServer> services_;

  Mailbox<Arrival> mailbox_{1};
  std::atomic<bool> stopping_{false};
  std::thread worker_;

  // Guards mode_ and the run's pointer. run_mutex_ is held while the worker processes a frame, so that a service
  // that ends a run waits for its frame (taken first when both are needed).
  std::mutex run_mutex_;
  std::mutex mutex_;
  Mode mode_ = Mode::kIdle;
  std::unique_ptr<RepeatRun> repeat_;
  bool localized_once_ = false;
  long malformed_ = 0;  // camera messages that could not be decoded, since the node started

  // The camera's latest CameraInfo (a teach run's map gets it) and, in a repeat run, the map's camera to check it
  // against once.
  std::mutex camera_mutex_;
  std::optional<Camera> camera_;
  std::optional<Camera> map_camera_;
  bool camera_checked_ = true;

  std::mutex log_mutex_;
  std::string last_problem_;
  ros::WallTime last_problem_time_;
};

}  // namespace vmap::ros_node
