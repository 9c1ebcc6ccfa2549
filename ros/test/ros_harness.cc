#include "ros_harness.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <thread>

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "vmap/sources/frame_source.h"
#include "vmap/sources/recording_reader.h"
#include "vmap/testing/recording_writer.h"
#include "vmap/testing/scoped_temp_dir.h"

#include "vmap_ros/camera_messages.h"

namespace vmap::ros_testing {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// A port of the loopback nobody listens on now: bound to port 0, read back, released. Another program could take
// it before the master does; the master then fails to start and RosMaster tries another.
int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof(address);
  if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    if (fd >= 0) close(fd);
    throw std::runtime_error("cannot find a free port on the loopback");
  }
  const int port = ntohs(address.sin_port);
  close(fd);
  return port;
}

bool Listening(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return false;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<uint16_t>(port));
  const bool connected = connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
  close(fd);
  return connected;
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const fs::path& log) : log_(log) {
  if (argv.empty()) throw std::invalid_argument("ChildProcess: no program");
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    // The child: a process group of its own (Stop() ends it and whatever it starts), killed with its parent.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    const int out = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (out >= 0) {
      dup2(out, STDOUT_FILENO);
      dup2(out, STDERR_FILENO);
      close(out);
    }
    const int null = open("/dev/null", O_RDONLY);
    if (null >= 0) dup2(null, STDIN_FILENO);
    std::vector<char*> args;
    for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  setpgid(pid_, pid_);  // also here: the group exists before either side goes on
}

ChildProcess::~ChildProcess() { Stop(); }

bool ChildProcess::Running() {
  if (exited_ || pid_ <= 0) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    exited_ = true;
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    kill(-pid_, SIGKILL);  // what it started, if anything is left
    return false;
  }
  return true;
}

int ChildProcess::Wait(std::chrono::seconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (Running()) {
    if (Clock::now() > deadline) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return status_;
}

int ChildProcess::Stop(std::chrono::seconds grace, int signal) {
  if (!Running()) return status_;
  kill(-pid_, signal);
  if (Wait(grace) == -1 && Running()) {
    kill(-pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
    exited_ = true;
    status_ = -1;
  }
  return status_;
}

std::string ChildProcess::Log() const { return testing::ReadText(log_); }

RosMaster& RosMaster::Get() {
  static RosMaster master;
  return master;
}

RosMaster::RosMaster() {
  // The folder outlives every test of the process (the master's and the nodes' logs); removed with the master.
  char pattern[] = "/tmp/vmap_rosmaster_XXXXXX";
  if (mkdtemp(pattern) == nullptr) throw std::runtime_error("cannot make a folder for the ROS master");
  folder_ = pattern;
  // Children (the node, rosbag play) inherit this process's environment.
  setenv("ROS_HOME", folder_.c_str(), 1);
  setenv("ROS_LOG_DIR", (folder_ / "log").c_str(), 1);
  setenv("ROS_HOSTNAME", "127.0.0.1", 1);
  std::string logs;
  for (int attempt = 0; attempt < 5 && uri_.empty(); ++attempt) {
    const int port = FreePort();
    process_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{VMAP_ROSMASTER, "--core", "-p", std::to_string(port), "-w", "3"},
        folder_ / ("rosmaster_" + std::to_string(port) + ".log"));
    // Up when it accepts connections; a master that could not bind its port has exited: another port.
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    while (process_->Running() && Clock::now() < deadline) {
      if (Listening(port)) {
        uri_ = "http://127.0.0.1:" + std::to_string(port) + "/";
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (uri_.empty()) logs += process_->Log();
  }
  if (uri_.empty()) throw std::runtime_error("rosmaster did not start:\n" + logs);
  setenv("ROS_MASTER_URI", uri_.c_str(), 1);
  ros::init(std::map<std::string, std::string>{{"__master", uri_}, {"__hostname", "127.0.0.1"}}, "vmap_test",
            ros::init_options::AnonymousName | ros::init_options::NoSigintHandler);
  ros::master::setRetryTimeout(ros::WallDuration(1.0));
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (!ros::master::check()) {
    if (Clock::now() > deadline)
      throw std::runtime_error("rosmaster at " + uri_ + " does not answer:\n" + process_->Log());
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ros::start();
}

RosMaster::~RosMaster() {
  ros::shutdown();
  process_.reset();
  std::error_code ignored;
  fs::remove_all(folder_, ignored);
}

fs::path VmapNodeBinary() { return VMAP_NODE_BINARY; }
fs::path SimulatorBinary() { return VMAP_SIMULATOR_BINARY; }

std::unique_ptr<ChildProcess> StartVmapNode(const std::string& ns, const std::vector<std::string>& arguments,
                                            const fs::path& log) {
  RosMaster::Get();  // its environment is this process's, which the node inherits
  std::vector<std::string> argv{VmapNodeBinary().string(), "__ns:=" + ns, "__name:=vmap"};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return std::make_unique<ChildProcess>(argv, log);
}

std::unique_ptr<ChildProcess> PlayBag(const fs::path& bag, double rate, const fs::path& log,
                                      const std::vector<std::string>& extra) {
  RosMaster::Get();
  std::vector<std::string> argv{VMAP_ROSBAG_PLAY, "--wait-for-subscribers", "--quiet", "--rate", std::to_string(rate)};
  argv.insert(argv.end(), extra.begin(), extra.end());
  argv.push_back(bag.string());
  return std::make_unique<ChildProcess>(argv, log);
}

bool WaitFor(const std::function<bool()>& done, std::chrono::seconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() > deadline || !ros::ok()) return done();
    ros::spinOnce();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

bool WaitForService(const std::string& name, std::chrono::seconds timeout) {
  return WaitFor([&] { return ros::service::exists(name, false); }, timeout);
}

bool WaitForNodeServices(const std::string& node, std::chrono::seconds timeout) {
  return WaitFor(
      [&] {
        for (const char* service :
             {"teach/start", "teach/stop", "repeat/start", "repeat/pause", "repeat/resume", "repeat/stop"}) {
          if (!ros::service::exists(node + "/" + service, false)) return false;
        }
        return true;
      },
      timeout);
}

sensor_msgs::Image GreyImage(int width, int height, double stamp, uint8_t level) {
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(stamp);
  image.header.frame_id = "camera";
  image.width = width;
  image.height = height;
  image.encoding = "mono8";
  image.step = width;
  image.data.assign(static_cast<size_t>(width) * height, level);
  return image;
}

std::vector<ros::Time> WriteVideoBag(const fs::path& video, int first, int last, const fs::path& bag,
                                     const std::string& encoding, double odometry_metres_per_frame) {
  FrameSourceOptions options;
  options.first = first;
  options.last = last;
  const std::unique_ptr<FrameSource> source = OpenFrameSource(video.string(), options);
  std::vector<testing::TestMessage> messages;
  std::vector<ros::Time> stamps;
  while (std::optional<Frame> frame = source->Next()) {
    const ros::Time stamp(1000.0 + std::max(0.0, frame->timestamp));
    const cv::Mat& pixels = encoding == "mono8" ? frame->gray : frame->color;
    sensor_msgs::Image image;
    image.header.seq = static_cast<uint32_t>(stamps.size());
    image.header.stamp = stamp;
    image.header.frame_id = "camera";
    image.height = pixels.rows;
    image.width = pixels.cols;
    image.encoding = encoding;
    image.step = static_cast<uint32_t>(pixels.cols * pixels.elemSize());
    image.data.resize(image.step * image.height);
    for (int y = 0; y < pixels.rows; ++y) std::memcpy(&image.data[y * image.step], pixels.ptr(y), image.step);
    if (const std::optional<Camera>& camera = source->info().camera) {
      sensor_msgs::CameraInfo info;
      info.header = image.header;
      info.width = image.width;
      info.height = image.height;
      info.distortion_model = "plumb_bob";
      info.D = {camera->k1, camera->k2, camera->p1, camera->p2, camera->k3};
      info.K = {camera->fx, 0, camera->cx, 0, camera->fy, camera->cy, 0, 0, 1};
      info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
      info.P = {camera->fx, 0, camera->cx, 0, 0, camera->fy, camera->cy, 0, 0, 0, 1, 0};
      messages.push_back({"/camera/camera_info", "sensor_msgs/CameraInfo", static_cast<int64_t>(stamp.toNSec()),
                          ros_node::SerializeMessage(info)});
    }
    if (odometry_metres_per_frame > 0.0) {
      nav_msgs::Odometry pose;
      pose.header.stamp = stamp;
      pose.header.frame_id = "odom";
      pose.pose.pose.position.x = odometry_metres_per_frame * static_cast<double>(stamps.size());
      pose.pose.pose.orientation.w = 1.0;
      messages.push_back(
          {"/odom", "nav_msgs/Odometry", static_cast<int64_t>(stamp.toNSec()), ros_node::SerializeMessage(pose)});
    }
    messages.push_back({"/camera/image_raw", "sensor_msgs/Image", static_cast<int64_t>(stamp.toNSec()),
                        ros_node::SerializeMessage(image)});
    stamps.push_back(stamp);
  }
  std::string why;
  if (!testing::WriteRos1Bag(bag.string(), messages, "none", &why)) throw std::runtime_error(why);
  return stamps;
}

void WriteBagSubset(const fs::path& bag, const std::vector<ros::Time>& stamps, const fs::path& subset) {
  const std::set<ros::Time> keep(stamps.begin(), stamps.end());
  const std::unique_ptr<RecordingReader> reader = OpenRecording(bag.string());
  std::map<std::string, std::string> types;
  for (const RecordingTopic& topic : reader->Topics()) types[topic.name] = topic.type;
  std::vector<testing::TestMessage> messages;
  RecordedMessage message;
  while (reader->Next({}, &message)) {
    if (types[message.topic] == "sensor_msgs/Image") {
      sensor_msgs::Image image;
      ros::serialization::IStream stream(message.data.data(), static_cast<uint32_t>(message.data.size()));
      ros::serialization::deserialize(stream, image);
      if (keep.count(image.header.stamp) == 0) continue;
    }
    messages.push_back({message.topic, types[message.topic], message.log_time_ns, message.data});
  }
  std::string why;
  if (!testing::WriteRos1Bag(subset.string(), messages, "none", &why)) throw std::runtime_error(why);
}

}  // namespace vmap::ros_testing
