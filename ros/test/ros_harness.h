#pragma once
// What the ROS tests share: a real ROS master on a free port for each test process (never a mock), child processes
// that are always killed (the master, the node, rosbag play), bags made from a shared video, and waiting for ROS
// without timing assumptions (every wait is for a condition, with a generous deadline).

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

namespace vmap::ros_testing {

// A program run in a process group of its own, its output in `log`. Destroying it ends it: SIGINT, then SIGKILL
// after a grace period, and the group's other processes with it. A test that fails or crashes leaves nothing.
class ChildProcess {
 public:
  ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool Running();
  // Waits for it to exit; its exit status, or -1 when it did not exit in `timeout` (then it runs on).
  int Wait(std::chrono::seconds timeout);
  // `signal` (SIGINT: what roslaunch sends first; SIGTERM: its escalation, and systemd's and docker's stop), up
  // to `grace` to exit, then SIGKILL. Returns the exit status (-1 after SIGKILL or a signal).
  int Stop(std::chrono::seconds grace = std::chrono::seconds(10), int signal = SIGINT);
  std::string Log() const;  // what it printed so far
  const std::filesystem::path& log() const { return log_; }

 private:
  int pid_ = -1;
  int status_ = -1;
  bool exited_ = false;
  std::filesystem::path log_;
};

// A rosmaster on a free port of the loopback, started for this test process, with its logs in a folder of its
// own; this process is initialised as a ROS node on it, and its environment (ROS_MASTER_URI, ROS_HOSTNAME,
// ROS_HOME) points the child processes at it. One per process: each test of the binary runs in its own
// process under ctest (gtest_discover_tests), and tests run one after the other in one process share it.
class RosMaster {
 public:
  static RosMaster& Get();  // starts it the first time (up to a minute while the machine is busy)
  const std::string& uri() const { return uri_; }
  const std::filesystem::path& folder() const { return folder_; }

 private:
  RosMaster();
  ~RosMaster();
  std::string uri_;
  std::filesystem::path folder_;
  std::unique_ptr<ChildProcess> process_;
};

// The node under test: vmap_node in namespace `ns`, named `name`, with its remappings and private parameters
// ("key:=value" and "_param:=value" arguments).
std::unique_ptr<ChildProcess> StartVmapNode(const std::string& ns, const std::vector<std::string>& arguments,
                                            const std::filesystem::path& log);

// rosbag play of `bag` (waits for a subscriber on each of its topics, then publishes at `rate` times the recorded
// rate).
std::unique_ptr<ChildProcess> PlayBag(const std::filesystem::path& bag, double rate, const std::filesystem::path& log,
                                      const std::vector<std::string>& extra = {});

// Waits until `done()` holds, spinning this process's callbacks, up to `timeout`. Returns done().
bool WaitFor(const std::function<bool()>& done, std::chrono::seconds timeout);
// Waits for service `name` to be advertised.
bool WaitForService(const std::string& name, std::chrono::seconds timeout = std::chrono::seconds(60));
// Waits for every service of the vmap node `node` ("/ns/vmap") to be advertised: the node is up. It advertises
// them one after the other, so that one is there says nothing of the next (on a loaded machine a call to a service
// not yet advertised fails at once).
bool WaitForNodeServices(const std::string& node, std::chrono::seconds timeout = std::chrono::seconds(60));

// A camera recording for the tests: frames [first, last] of a video as sensor_msgs/Image (`encoding`: bgr8 or
// mono8) on /camera/image_raw with the video's intrinsics as CameraInfo on /camera/camera_info, stamped from
// 1000 s plus the video's time; with `odometry_metres_per_frame` above 0, a nav_msgs/Odometry on /odom at each
// frame's stamp (the robot that much further along x at each frame). Returns the frames' stamps.
std::vector<ros::Time> WriteVideoBag(const std::filesystem::path& video, int first, int last,
                                     const std::filesystem::path& bag, const std::string& encoding = "bgr8",
                                     double odometry_metres_per_frame = 0.0);

// The frames of `bag` whose image stamps are in `stamps`, with every camera_info message, as a new bag (what a
// node processed, for `vmap localize` to localize the same frames).
void WriteBagSubset(const std::filesystem::path& bag, const std::vector<ros::Time>& stamps,
                    const std::filesystem::path& subset);

// A mono8 image of one grey level, stamped `stamp` seconds.
sensor_msgs::Image GreyImage(int width, int height, double stamp, uint8_t level = 128);

// The vmap_node and vmap_simulator binaries of this build.
std::filesystem::path VmapNodeBinary();
std::filesystem::path SimulatorBinary();

}  // namespace vmap::ros_testing
