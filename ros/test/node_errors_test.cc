// The node against bad input on a real ROS master: malformed camera messages, a NaN CameraInfo, a missing map,
// services called in the wrong state. Each gets a clear answer or log line; the node keeps running, and nothing
// on disk is lost.

#include <atomic>
#include <chrono>
#include <csignal>
#include <fstream>
#include <functional>
#include <mutex>
#include <thread>

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Trigger.h>

#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

#include "ros_harness.h"
#include "vmap_ros/Localization.h"
#include "vmap_ros/StartRepeat.h"
#include "vmap_ros/StartTeach.h"

namespace vmap::ros_testing {
namespace {

namespace fs = std::filesystem;
using testing::Quote;
using testing::RunVmap;
using testing::ScopedTempDir;
using testing::SharedDir;

constexpr auto kTimeout = std::chrono::seconds(60);

std::string Trigger(const std::string& service, bool* success) {
  std_srvs::Trigger call;
  EXPECT_TRUE(ros::service::call(service, call)) << service;
  *success = call.response.success;
  return call.response.message;
}

// Started before its master, a node waits for it, says where it looks, and still stops on SIGINT or SIGTERM with a
// shell's status (roscpp would retry the master for ever, and the nodes' own handlers only set a flag).
TEST(NodeErrors, ANodeWaitingForItsMasterStopsOnASignal) {
  ScopedTempDir dir("ros_no_master");
  const std::vector<std::pair<fs::path, int>> cases = {{VmapNodeBinary(), SIGTERM}, {SimulatorBinary(), SIGINT}};
  for (const auto& [binary, signal] : cases) {
    ChildProcess node({binary.string(), "__master:=http://127.0.0.1:9", "__name:=waiting"},
                      dir.path() / (binary.filename().string() + ".log"));
    // No master here: WaitFor, which spins this test's own node, is of no use.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (node.Log().find("waiting for the ROS master at http://127.0.0.1:9") == std::string::npos &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_NE(node.Log().find("waiting for the ROS master at http://127.0.0.1:9"), std::string::npos) << node.Log();
    EXPECT_EQ(node.Stop(std::chrono::seconds(5), signal), 128 + signal) << node.Log();
  }
}

TEST(NodeErrors, BadMessagesMapsAndCallsAreAnsweredAndTheNodeRunsOn) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_errors");
  const std::string ns = "/errors_test";
  const auto node = StartVmapNode(ns, {"image:=/errors/image_raw"}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices(ns + "/vmap")) << node->Log();

  // Services in the wrong state.
  bool success = true;
  EXPECT_NE(Trigger(ns + "/vmap/repeat/pause", &success).find("no repeat run is in progress"), std::string::npos);
  EXPECT_FALSE(success);
  EXPECT_NE(Trigger(ns + "/vmap/repeat/resume", &success).find("no repeat run is in progress"), std::string::npos);
  EXPECT_FALSE(success);
  EXPECT_NE(Trigger(ns + "/vmap/repeat/stop", &success).find("no repeat run is in progress"), std::string::npos);
  EXPECT_FALSE(success);

  // A missing map, a folder that is not a map (its file stays as it was), no map at all.
  vmap_ros::StartRepeat start;
  start.request.map = (dir.path() / "no_such_map").string();
  start.request.goal = -1;
  start.request.start = -1;
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", start));
  EXPECT_FALSE(start.response.success);
  EXPECT_NE(start.response.message.find("no_such_map"), std::string::npos) << start.response.message;
  fs::create_directories(dir.path() / "notes");
  std::ofstream(dir.path() / "notes" / "todo.txt") << "my notes\n";
  start.request.map = (dir.path() / "notes").string();
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", start));
  EXPECT_FALSE(start.response.success);
  EXPECT_NE(start.response.message.find("notes"), std::string::npos) << start.response.message;
  EXPECT_EQ(testing::ReadText(dir.path() / "notes" / "todo.txt"), "my notes\n");
  start.request.map = "";
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", start));
  EXPECT_FALSE(start.response.success);
  EXPECT_NE(start.response.message.find("~map"), std::string::npos) << start.response.message;

  // A real map; a goal it does not have; then a repeat run, and a second start while it runs.
  const fs::path bag = dir.path() / "teach.bag", map = dir.path() / "map";
  WriteVideoBag(fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4", 0, 59, bag);
  std::string output;
  ASSERT_EQ(RunVmap("build -q " + Quote(bag) + " -o " + Quote(map), &output), 0) << output;
  start.request.map = map.string();
  start.request.goal = 1000;
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", start));
  EXPECT_FALSE(start.response.success);
  EXPECT_NE(start.response.message.find("goal 1000 is no key image"), std::string::npos) << start.response.message;
  start.request.goal = -1;
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", start));
  EXPECT_FALSE(start.response.success);
  EXPECT_NE(start.response.message.find("in progress"), std::string::npos) << start.response.message;
  EXPECT_NE(Trigger(ns + "/vmap/repeat/resume", &success).find("not paused"), std::string::npos);
  EXPECT_FALSE(success);

  // Malformed camera messages, one at a time: each is logged (the node takes the newest frame, so the next is
  // sent once the last was seen), then a good frame is still localized.
  ros::NodeHandle handle;
  ros::Publisher images = handle.advertise<sensor_msgs::Image>("/errors/image_raw", 10);
  ros::Publisher infos = handle.advertise<sensor_msgs::CameraInfo>("/errors/camera_info", 10);
  ASSERT_TRUE(WaitFor([&] { return images.getNumSubscribers() > 0 && infos.getNumSubscribers() > 0; }, kTimeout));
  std::mutex mutex;
  std::vector<vmap_ros::Localization> localizations;
  const ros::Subscriber subscriber = handle.subscribe<vmap_ros::Localization>(
      ns + "/vmap/localization", 100, [&](const vmap_ros::Localization::ConstPtr& message) {
        std::lock_guard<std::mutex> lock(mutex);
        localizations.push_back(*message);
      });
  ASSERT_TRUE(WaitFor([&] { return subscriber.getNumPublishers() > 0; }, kTimeout));
  const auto logged = [&](const std::string& text) {
    return WaitFor([&] { return node->Log().find(text) != std::string::npos; }, kTimeout);
  };
  // A frame that is no image stops the robot: the base is not left with the last command.
  int stops = 0;
  const ros::Subscriber commands =
      handle.subscribe<geometry_msgs::Twist>(ns + "/cmd_vel", 100, [&](const geometry_msgs::Twist::ConstPtr& twist) {
        std::lock_guard<std::mutex> lock(mutex);
        stops += twist->linear.x == 0.0 && twist->angular.z == 0.0 ? 1 : 0;
      });
  ASSERT_TRUE(WaitFor([&] { return commands.getNumPublishers() > 0; }, kTimeout));

  sensor_msgs::Image short_data = GreyImage(640, 480, 1.0);
  short_data.data.resize(1000);
  images.publish(short_data);
  EXPECT_TRUE(logged("640x480 mono8 with step 640 needs more than its 1000 bytes")) << node->Log();
  sensor_msgs::Image short_step = GreyImage(640, 480, 2.0);
  short_step.encoding = "bgr8";  // 640 bytes a row cannot hold 640 BGR pixels
  images.publish(short_step);
  EXPECT_TRUE(logged("640x480 bgr8 with step 640")) << node->Log();
  sensor_msgs::Image unknown = GreyImage(640, 480, 3.0);
  unknown.encoding = "yuv422_weird";
  images.publish(unknown);
  EXPECT_TRUE(logged("has image encoding 'yuv422_weird'")) << node->Log();
  // Three frames that are no images, three stops (one is enough, should the first leave before the link is up).
  EXPECT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return stops > 0;
      },
      kTimeout));
  sensor_msgs::CameraInfo nan_info;
  nan_info.width = 640;
  nan_info.height = 480;
  nan_info.distortion_model = "plumb_bob";
  nan_info.K = {std::nan(""), 0, 320, 0, 500, 240, 0, 0, 1};
  infos.publish(nan_info);
  // The camera's rule is vmap's (its advice may follow the reason); the node then ignores the message.
  EXPECT_TRUE(logged("has a parameter that is not a finite number")) << node->Log();
  EXPECT_TRUE(logged("the message is ignored")) << node->Log();

  images.publish(GreyImage(640, 480, 4.0));
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return !localizations.empty();
      },
      kTimeout))
      << node->Log();
  {
    std::lock_guard<std::mutex> lock(mutex);
    ASSERT_EQ(localizations.size(), 1u);  // only the good frame
    EXPECT_EQ(localizations.front().header.stamp, ros::Time(4.0));
    EXPECT_EQ(localizations.front().status_name, "lost");  // a grey frame shows nothing of the map
  }

  // Pause twice, resume, stop twice: the second of each is refused.
  EXPECT_TRUE((Trigger(ns + "/vmap/repeat/pause", &success), success));
  EXPECT_NE(Trigger(ns + "/vmap/repeat/pause", &success).find("paused already"), std::string::npos);
  EXPECT_FALSE(success);
  EXPECT_TRUE((Trigger(ns + "/vmap/repeat/resume", &success), success));
  EXPECT_TRUE((Trigger(ns + "/vmap/repeat/stop", &success), success));
  EXPECT_FALSE((Trigger(ns + "/vmap/repeat/stop", &success), success));
  EXPECT_TRUE(node->Running()) << node->Log();
  EXPECT_EQ(node->Stop(), 0) << node->Log();  // SIGINT: a clean exit
}

// A teach run is no repeat run: the repeat services called during one are refused and the teach run goes on (they
// crashed the node). Two starts called at once are one run, not two.
TEST(NodeErrors, RepeatCallsDuringATeachRunAndStartsAtOnceAreRefused) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_modes");
  const std::string ns = "/modes_test";
  const auto node = StartVmapNode(ns, {"image:=/modes/image_raw"}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices(ns + "/vmap")) << node->Log();
  vmap_ros::StartTeach teach;
  teach.request.map = (dir.path() / "taught").string();
  ASSERT_TRUE(ros::service::call(ns + "/vmap/teach/start", teach));
  ASSERT_TRUE(teach.response.success) << teach.response.message;
  bool success = true;
  for (const char* service : {"/vmap/repeat/pause", "/vmap/repeat/resume", "/vmap/repeat/stop"}) {
    EXPECT_NE(Trigger(ns + service, &success).find("no repeat run is in progress"), std::string::npos) << service;
    EXPECT_FALSE(success) << service;
  }
  EXPECT_TRUE(node->Running()) << node->Log();
  // Still the teach run's to stop (no frame came, so it has no map to write), said in the node's words: its topic.
  const std::string stopped = Trigger(ns + "/vmap/teach/stop", &success);
  EXPECT_FALSE(success);
  EXPECT_NE(stopped.find("no frame came on /modes/image_raw during the run"), std::string::npos) << stopped;
  EXPECT_EQ(stopped.find("--first"), std::string::npos) << stopped;

  // Values the services and parameters do not take.
  vmap_ros::StartRepeat repeat;
  repeat.request.map = (dir.path() / "map").string();
  repeat.request.start = -2;
  repeat.request.goal = -1;
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", repeat));
  EXPECT_FALSE(repeat.response.success);
  EXPECT_NE(repeat.response.message.find("start -2 and goal -1: each is a key image"), std::string::npos)
      << repeat.response.message;
  ros::param::set(ns + "/vmap/teach_queue", 1.5);
  ASSERT_TRUE(ros::service::call(ns + "/vmap/teach/start", teach));
  EXPECT_FALSE(teach.response.success);
  EXPECT_NE(teach.response.message.find("~teach_queue must be an integer"), std::string::npos)
      << teach.response.message;
  ros::param::del(ns + "/vmap/teach_queue");
  ros::param::set(ns + "/vmap/topic", "/camera/image_raw");  // vmap localize's flag for recordings, set after start-up
  repeat.request.start = -1;
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", repeat));
  EXPECT_FALSE(repeat.response.success);
  EXPECT_NE(repeat.response.message.find("~topic is vmap's option for recordings"), std::string::npos)
      << repeat.response.message;
  ros::param::del(ns + "/vmap/topic");
  // vmap build's -o and a stream's timeout: the node's map is the request's, its input the image topic.
  teach.request.map = (dir.path() / "never").string();
  for (const char* name : {"output", "stream_timeout"}) {
    if (name == std::string("output")) {
      ros::param::set(ns + "/vmap/output", std::string("elsewhere"));
    } else {
      ros::param::set(ns + "/vmap/stream_timeout", 2.0);
    }
    ASSERT_TRUE(ros::service::call(ns + "/vmap/teach/start", teach));
    EXPECT_FALSE(teach.response.success) << name;
    EXPECT_NE(teach.response.message.find(std::string("~") + name + " is vmap"), std::string::npos)
        << teach.response.message;
    ros::param::del(ns + "/vmap/" + name);
  }
  EXPECT_FALSE(fs::exists(dir.path() / "never"));

  // A repeat run's start reads its map for a while: a teach run started meanwhile is refused, or starts first and
  // the repeat run is refused, never both.
  const fs::path bag = dir.path() / "teach.bag";
  WriteVideoBag(fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4", 0, 29, bag);
  std::string output;
  ASSERT_EQ(RunVmap("build -q " + Quote(bag) + " -o " + Quote(dir.path() / "map"), &output), 0) << output;
  repeat.request.start = -1;
  for (int attempt = 0; attempt < 3; ++attempt) {
    std::thread repeat_call([&] { ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", repeat)); });
    ASSERT_TRUE(ros::service::call(ns + "/vmap/teach/start", teach));
    repeat_call.join();
    EXPECT_NE(repeat.response.success, teach.response.success) << repeat.response.message << "\n"
                                                               << teach.response.message;
    const std::string refused = repeat.response.success ? teach.response.message : repeat.response.message;
    EXPECT_TRUE(refused.find("in progress") != std::string::npos ||
                refused.find("another run is starting") != std::string::npos)
        << refused;
    Trigger(ns + (repeat.response.success ? "/vmap/repeat/stop" : "/vmap/teach/stop"), &success);
  }
  EXPECT_TRUE(node->Running()) << node->Log();
  EXPECT_EQ(node->Stop(), 0) << node->Log();
}

// Starts and stops called at once from several clients while the camera sends frames: each service is answered on
// a spinner thread of its own, and a stop that unsubscribed the camera while a start subscribed it corrupted the
// node's memory (it crashed within seconds). The node stays up and a repeat run started afterwards is localized.
TEST(NodeErrors, StartsAndStopsCalledAtOnceNeverBreakTheNode) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_transitions");
  const std::string ns = "/transitions_test";
  const fs::path bag = dir.path() / "teach.bag", map = dir.path() / "map";
  WriteVideoBag(fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4", 0, 59, bag);
  std::string output;
  ASSERT_EQ(RunVmap("build -q " + Quote(bag) + " -o " + Quote(map), &output), 0) << output;
  const auto node = StartVmapNode(ns, {"image:=/transitions/image_raw"}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices(ns + "/vmap")) << node->Log();
  ros::NodeHandle handle;
  ros::Publisher images = handle.advertise<sensor_msgs::Image>("/transitions/image_raw", 10);
  std::atomic<bool> done{false};
  std::thread camera([&] {
    for (double stamp = 1.0; !done; stamp += 0.02) {
      images.publish(GreyImage(640, 480, stamp));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  const auto hammer = [&](const std::function<void()>& call) {
    return std::thread([&, call] {
      const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(8);
      while (std::chrono::steady_clock::now() < end && node->Running()) call();
    });
  };
  std::vector<std::thread> clients;
  clients.push_back(hammer([&] {
    vmap_ros::StartRepeat start;
    start.request.map = map.string();
    start.request.start = start.request.goal = -1;
    ros::service::call(ns + "/vmap/repeat/start", start);
  }));
  clients.push_back(hammer([&] {
    vmap_ros::StartTeach start;
    start.request.map = (dir.path() / "taught").string();
    ros::service::call(ns + "/vmap/teach/start", start);
  }));
  for (const char* stop : {"/vmap/repeat/stop", "/vmap/teach/stop", "/vmap/repeat/pause"}) {
    clients.push_back(hammer([&, stop] {
      std_srvs::Trigger call;
      ros::service::call(ns + stop, call);
    }));
  }
  for (std::thread& client : clients) client.join();
  done = true;
  camera.join();
  ASSERT_TRUE(node->Running()) << node->Log();
  bool success = false;
  Trigger(ns + "/vmap/teach/stop", &success);
  Trigger(ns + "/vmap/repeat/stop", &success);
  vmap_ros::StartRepeat start;
  start.request.map = map.string();
  start.request.start = start.request.goal = -1;
  ASSERT_TRUE(ros::service::call(ns + "/vmap/repeat/start", start));
  EXPECT_TRUE(start.response.success) << start.response.message;
  std::atomic<int> localized{0};
  const ros::Subscriber localizations = handle.subscribe<vmap_ros::Localization>(
      ns + "/vmap/localization", 10, [&](const vmap_ros::Localization::ConstPtr&) { ++localized; });
  images.publish(GreyImage(640, 480, 100.0));
  EXPECT_TRUE(WaitFor(
      [&] {
        images.publish(GreyImage(640, 480, 100.0 + 0.1 * localized));
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        return localized > 0;
      },
      kTimeout))
      << node->Log();
  EXPECT_EQ(node->Stop(), 0) << node->Log();
}

}  // namespace
}  // namespace vmap::ros_testing
