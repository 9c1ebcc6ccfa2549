// Latency and coverage of the node's repeat run (docs/ros.md, "Measured"): camera frames published at a camera's
// rate to a real node on a real master, and the time from each image's publication to the node's command and
// localization message for it.
//
//   ros_latency_bench [--frames N] [--rate HZ] [--matcher orb|xfeat|...]
//
// The map: `vmap build` on ../shared/data/lab_floor/lab_floor.mp4 (640x480). The camera: the same video's first N
// frames (default 300), published as sensor_msgs/Image bgr8 at HZ (default 30) by this process, each stamped with
// the time it is published; the node runs as its own process. Latency to the command: from that stamp to this
// process receiving the frame's cmd_vel (the k-th command is the k-th frame processed, paired with the k-th
// localization message by order); to the localization message likewise. Coverage: the frames that got a command
// and a localization message, of those published (the node drops a frame that arrives while it is busy).

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include "vmap/core/runtime.h"
#include "vmap/sources/frame_source.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

#include "ros_harness.h"
#include "vmap_ros/Localization.h"
#include "vmap_ros/StartRepeat.h"

namespace {

using namespace vmap;
using namespace vmap::ros_testing;
namespace fs = std::filesystem;

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  const size_t at = std::min(values.size() - 1, static_cast<size_t>(p / 100.0 * (values.size() - 1) + 0.5));
  return values[at];
}

struct Received {
  std::mutex mutex;
  std::vector<vmap_ros::Localization> localizations;
  std::vector<double> localization_times;  // ROS time of receipt
  std::vector<double> command_times;
};

}  // namespace

int main(int argc, char** argv) {
  RuntimeOptions runtime;
  runtime.handle_interrupts = false;
  InitializeRuntime(runtime);
  int frames = 300;
  double rate = 30.0;
  std::string matcher = "orb";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--frames") == 0) frames = std::stoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--rate") == 0) rate = std::stod(argv[i + 1]);
    if (std::strcmp(argv[i], "--matcher") == 0) matcher = argv[i + 1];
  }
  const fs::path video = fs::path(VMAP_SHARED_DIR) / "data/lab_floor/lab_floor.mp4";
  testing::ScopedTempDir dir("ros_latency");
  const fs::path map = dir.path() / "map";
  std::string output;
  if (testing::RunVmap("build -q " + testing::Quote(video) + " --matcher " + matcher + " -o " + testing::Quote(map),
                       &output) != 0) {
    std::fprintf(stderr, "ros_latency_bench: vmap build failed:\n%s\n", output.c_str());
    return 1;
  }

  // The camera's frames, ready to publish.
  FrameSourceOptions source_options;
  source_options.last = frames - 1;
  const std::unique_ptr<FrameSource> source = OpenFrameSource(video.string(), source_options);
  std::vector<sensor_msgs::Image> images;
  while (std::optional<Frame> frame = source->Next()) {
    sensor_msgs::Image image;
    image.header.frame_id = "camera";
    image.height = frame->color.rows;
    image.width = frame->color.cols;
    image.encoding = "bgr8";
    image.step = static_cast<uint32_t>(frame->color.cols * 3);
    image.data.resize(image.step * image.height);
    for (int y = 0; y < frame->color.rows; ++y)
      std::memcpy(&image.data[y * image.step], frame->color.ptr(y), image.step);
    images.push_back(std::move(image));
  }

  RosMaster::Get();
  const auto node =
      StartVmapNode("/bench", {"image:=/bench/camera/image_raw", "cmd_vel:=/bench/cmd_vel"}, dir.path() / "node.log");
  if (!WaitForNodeServices("/bench/vmap")) {
    std::fprintf(stderr, "ros_latency_bench: the node did not start:\n%s\n", node->Log().c_str());
    return 1;
  }
  ros::NodeHandle handle;
  Received received;
  const ros::Subscriber localizations = handle.subscribe<vmap_ros::Localization>(
      "/bench/vmap/localization", 10000,
      [&](const vmap_ros::Localization::ConstPtr& message) {
        const double now = ros::Time::now().toSec();
        std::lock_guard<std::mutex> lock(received.mutex);
        received.localizations.push_back(*message);
        received.localization_times.push_back(now);
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  const ros::Subscriber commands = handle.subscribe<geometry_msgs::Twist>(
      "/bench/cmd_vel", 10000,
      [&](const geometry_msgs::Twist::ConstPtr&) {
        const double now = ros::Time::now().toSec();
        std::lock_guard<std::mutex> lock(received.mutex);
        received.command_times.push_back(now);
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ros::Publisher camera = handle.advertise<sensor_msgs::Image>("/bench/camera/image_raw", 1);
  ros::AsyncSpinner spinner(2);
  spinner.start();

  vmap_ros::StartRepeat start;
  start.request.map = map.string();
  start.request.goal = -1;
  start.request.start = -1;
  if (!ros::service::call("/bench/vmap/repeat/start", start) || !start.response.success) {
    std::fprintf(stderr, "ros_latency_bench: repeat/start failed: %s\n%s\n", start.response.message.c_str(),
                 node->Log().c_str());
    return 1;
  }
  const auto connected = [&] {
    return camera.getNumSubscribers() > 0 && localizations.getNumPublishers() > 0 && commands.getNumPublishers() > 0;
  };
  for (int i = 0; i < 6000 && !connected(); ++i) ros::WallDuration(0.01).sleep();
  const size_t commands_before = received.command_times.size();  // repeat/start's zero command, if any

  ros::WallRate pace(rate);
  for (sensor_msgs::Image& image : images) {
    image.header.stamp = ros::Time::now();
    camera.publish(image);
    pace.sleep();
  }
  // The last frame is always processed: wait for it.
  const ros::Time last = images.back().header.stamp;
  for (int i = 0; i < 6000; ++i) {
    {
      std::lock_guard<std::mutex> lock(received.mutex);
      if (!received.localizations.empty() && received.localizations.back().header.stamp == last) break;
    }
    ros::WallDuration(0.01).sleep();
  }
  ros::WallDuration(0.5).sleep();  // the last commands in flight

  std::lock_guard<std::mutex> lock(received.mutex);
  std::vector<double> to_localization, to_command, in_node;
  size_t dropped = 0;
  for (size_t k = 0; k < received.localizations.size(); ++k) {
    const double stamp = received.localizations[k].header.stamp.toSec();
    to_localization.push_back(1000.0 * (received.localization_times[k] - stamp));
    in_node.push_back(1000.0 * received.localizations[k].latency);
    dropped += received.localizations[k].frames_dropped;
    const size_t command = commands_before + k;
    if (command < received.command_times.size())
      to_command.push_back(1000.0 * (received.command_times[command] - stamp));
  }
  const size_t processed = received.localizations.size();
  std::printf("ros_latency_bench: matcher %s, %zu frames of %dx%d published at %.0f Hz\n", matcher.c_str(),
              images.size(), images.front().width, images.front().height, rate);
  std::printf("localization messages  %zu (%.1f %% of frames), frames dropped by the node %zu\n", processed,
              100.0 * processed / images.size(), dropped);
  std::printf("commands (cmd_vel)     %zu (%.1f %% of frames)\n", to_command.size(),
              100.0 * to_command.size() / images.size());
  std::printf("latency image -> command       median %.1f ms, 95th percentile %.1f ms\n", Percentile(to_command, 50),
              Percentile(to_command, 95));
  std::printf("latency image -> localization  median %.1f ms, 95th percentile %.1f ms\n",
              Percentile(to_localization, 50), Percentile(to_localization, 95));
  std::printf("in the node (arrival -> publication)  median %.1f ms, 95th percentile %.1f ms\n",
              Percentile(in_node, 50), Percentile(in_node, 95));
  spinner.stop();
  return 0;
}
