#pragma once
// The vmap node (docs/ros.md): teach and repeat on a robot.
//
// Topics (remappable):      image (sensor_msgs/Image or CompressedImage), camera_info (beside image, as
//                           image_transport pairs them, or ~camera_topic), odom (nav_msgs/Odometry, when the
//                           robot has it: the controller reads it at each frame's time); publishes cmd_vel
//                           (geometry_msgs/Twist, one per frame a repeat run processes, and a zero one at a
//                           pause or stop).
// Private topics:           ~localization (vmap_ros/Localization, one per frame a repeat run processes),
//                           ~debug_image (sensor_msgs/Image, drawn only while someone subscribes; a plain publisher,
//                           since Debian's image_transport cannot be linked: it needs a ROS 1 pluginlib),
//                           ~localized (std_msgs/Bool, latched: true once a repeat run's first frame is localized),
//                           ~teach/progress (vmap_ros/TeachProgress, after every frame a teach run takes).
// Services:                 ~teach/start, ~teach/stop, ~repeat/start, ~repeat/pause, ~repeat/resume, ~repeat/stop.
// Parameters:               the flags of `vmap build` (teach) and `vmap localize` (repeat) by their names
//                           (parameter_reader.h), read when a run starts; ~map, the map directory; ~teach_queue.
//
// Threads: ROS's spinner threads run the callbacks and services; a camera callback only hands the message on. In
// a repeat run it goes to a mailbox of one frame (mailbox.h) that one worker thread empties: the worker always
// takes the newest frame, so a slow frame delays no other (frames arriving meanwhile are dropped and counted in the
// next message's frames_dropped). In a teach run it goes to the build pipeline's source (topic_frame_source.h),
// which holds ~teach_queue frames: every frame counts towards the map. No error of a message, a map or a service
// call ends the node: each is answered or logged, and the node goes on.

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <std_srvs/Trigger.h>
#include <topic_tools/shape_shifter.h>

#include "vmap_ros/StartRepeat.h"
#include "vmap_ros/StartTeach.h"
#include "vmap_ros/mailbox.h"
#include "vmap_ros/odometry_buffer.h"
#include "vmap_ros/repeat_run.h"
#include "vmap_ros/teach_run.h"

namespace vmap::ros_node {

class VmapNode {
 public:
  // `node`: the namespace of the topics (image, camera_info, cmd_vel); `private_node`: "~".
  VmapNode(const ros::NodeHandle& node, const ros::NodeHandle& private_node);
  // Ends the node's work while ROS is still up: a repeat run's robot gets a zero command, a teach run still going is
  // finished (its map and odometry written, as ~teach/stop writes them). Returns false when that map could not be
  // written. Once; the destructor calls it when main did not.
  bool Stop();
  // A repeat run's robot gets a zero command at once, and no other command from then on: for a node about to lose its
  // connections (the ROS master asked it to shut down: another node registered under its name, `rosnode kill`),
  // before Stop() does the rest. Callable from any thread.
  void HaltRobot();
  ~VmapNode();
  VmapNode(const VmapNode&) = delete;
  VmapNode& operator=(const VmapNode&) = delete;

 private:
  // kStarting: a start service is reading its parameters and map, the node claimed so that a second start called
  // meanwhile is refused (two starts at once both succeeded). kFinishing: a teach run's map is being written; no
  // run starts meanwhile.
  enum class Mode { kIdle, kStarting, kTeaching, kFinishing, kRepeating, kPaused };
  struct Arrival {
    topic_tools::ShapeShifter::ConstPtr message;
    ros::WallTime time;  // when the callback got it
  };

  // vmap_node.cc: the camera, the worker, what both runs share.
  void OnImage(const topic_tools::ShapeShifter::ConstPtr& message);
  void OnCameraInfo(const sensor_msgs::CameraInfo::ConstPtr& info);
  void SubscribeCamera();
  void UnsubscribeCamera();
  void Work();
  // Why a run cannot start now ("a teach run is in progress; ..."); "" when the node is idle. Under mutex_.
  std::string Busy() const;
  // Throws InputError for a parameter that names a recording to read (~topic, ~format): the node reads its topics.
  void RefuseRecordingParameters() const;
  // The teach runs' parameters that are set (~tau, ~resize, ~camera, ...), which a repeat run does not read: it takes
  // them from the map. Said at repeat/start, so that a value there is not taken to apply.
  std::vector<std::string> TeachParametersSet() const;
  // Claims the idle node for a run being started ("" when claimed, else why not: Busy()); a StartClaim made then
  // gives it back idle when the start fails, unless kept once the run is set.
  std::string ClaimForStart();
  void ReleaseClaim();
  class StartClaim {
   public:
    explicit StartClaim(VmapNode* node) : node_(node) {}
    StartClaim(const StartClaim&) = delete;
    StartClaim& operator=(const StartClaim&) = delete;
    ~StartClaim() {
      if (node_) node_->ReleaseClaim();
    }
    void Keep() { node_ = nullptr; }

   private:
    VmapNode* node_;
  };
  std::string MapOf(const std::string& requested) const;
  // Logs an error of a message: at once when its problem differs from the last one logged, else at most every
  // few seconds (a camera sending one malformed message 30 times a second would flood the log).
  void LogMessageError(const std::string& text, const std::string& problem);
  // Every parameter the node reads, for the warning about the others.
  std::set<std::string> KnownParameters() const;

  // teach_mode.cc
  bool StartTeach(vmap_ros::StartTeach::Request& request, vmap_ros::StartTeach::Response& response);
  bool StopTeach(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  // Stops `run` (taken from teach_) and writes its map and the odometry recorded meanwhile; returns whether it was
  // written, and `answer` says what was written or why not. Leaves the node idle.
  bool FinishTeach(std::unique_ptr<TeachRun> run, std::string* answer);
  void PublishTeachProgress();

  // repeat_mode.cc
  bool StartRepeat(vmap_ros::StartRepeat::Request& request, vmap_ros::StartRepeat::Response& response);
  bool PauseRepeat(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool ResumeRepeat(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool StopRepeat(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  void OnOdometry(const nav_msgs::Odometry::ConstPtr& odometry);
  void RepeatFrame(const Arrival& arrival);
  void PublishStop();
  // A stop between two frames of a repeat run that the controller did not command (a frame that cannot be read, a
  // quiet camera): the controller is told, so that it starts again from rest. Called with run_mutex_ held.
  void StopBetweenFrames();
  // Every command goes out here: none but zero once HaltRobot() has run.
  void PublishCommand(const geometry_msgs::Twist& command);
  // A repeat run's camera that has sent no frame for ~camera_timeout seconds: the robot stops until frames come.
  void StopIfCameraQuiet();
  // The private parameter `name`, seconds in [0, 3600], checked (InputError saying what it is: `meaning`);
  // `unset` when it is not set.
  double ReadSeconds(const char* name, double unset, const char* meaning) const;

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  std::string image_topic_;
  std::string camera_info_topic_;

  ros::Subscriber image_subscriber_;
  ros::Subscriber camera_info_subscriber_;
  ros::Subscriber odometry_subscriber_;
  ros::Publisher cmd_vel_;
  ros::Publisher localization_;
  ros::Publisher localized_;
  ros::Publisher debug_image_;
  ros::Publisher teach_progress_;
  std::vector<ros::ServiceServer> services_;

  Mailbox<Arrival> mailbox_{1};
  std::atomic<bool> stopping_{false};
  std::mutex command_mutex_;  // guards halted_ and orders the commands around it
  bool halted_ = false;
  bool stopped_ = false;  // Stop() has run
  std::thread worker_;

  // One start or stop of a run at a time, and Stop() after any in progress: the services are answered on several
  // spinner threads, and a stop that unsubscribed while a start subscribed corrupted the subscribers (a crash), or
  // left the new run without its camera. Taken before run_mutex_ and mutex_; the callbacks never take it.
  std::mutex transitions_mutex_;
  // mutex_ guards mode_ and the runs' pointers. run_mutex_ is held while the worker processes a frame, so that a
  // service that ends a repeat run waits for its frame (taken first when both are needed).
  std::mutex run_mutex_;
  mutable std::mutex mutex_;
  Mode mode_ = Mode::kIdle;
  std::unique_ptr<RepeatRun> repeat_;
  std::unique_ptr<TeachRun> teach_;
  bool localized_once_ = false;
  bool goal_reached_ = false;
  // The camera watchdog (worker thread only, but for camera_timeout_, set at a start before frames come).
  double camera_timeout_ = 1.0;  // seconds; 0 = none
  double odom_wait_ = 0.0;       // ~odom_wait: seconds a frame waits for the odometry of its time; 0 = none
  ros::WallTime last_frame_;     // when the repeat run started or last processed a frame
  bool quiet_stopped_ = false;   // the watchdog stopped the robot and no frame has come since
  OdometryBuffer odometry_;
  // A teach run's odometry, written into each of its snapshots and its map (BuildPipelineOptions::write_beside_map).
  std::mutex teach_odometry_mutex_;
  bool recording_teach_odometry_ = false;
  std::vector<OdometrySample> teach_odometry_;
  long malformed_ = 0;  // camera messages a repeat run could not decode, since the node started
  std::atomic<long> teach_frames_{0};
  std::atomic<long> teach_dropped_{0};

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
