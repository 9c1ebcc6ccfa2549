// The node's teach run on a real ROS master: a bag made from a shared video is played to it, and the map it
// writes is compared with `vmap build` on the same bag.

#include <fstream>
#include <mutex>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Trigger.h>

#include "vmap/map/map_io.h"
#include "vmap/sources/odometry.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

#include "ros_harness.h"
#include "vmap_ros/StartTeach.h"
#include "vmap_ros/TeachProgress.h"

namespace vmap::ros_testing {
namespace {

namespace fs = std::filesystem;
using testing::Quote;
using testing::RunVmap;
using testing::ScopedTempDir;
using testing::SharedDir;

constexpr auto kTimeout = std::chrono::seconds(120);

TEST(TeachNode, BuildsFromAPlayedBagTheMapVmapBuildBuilds) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_teach");
  const fs::path bag = dir.path() / "teach.bag";
  const std::vector<ros::Time> stamps =
      WriteVideoBag(fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4", 0, 239, bag, "bgr8", 0.05);
  std::string output;
  ASSERT_EQ(RunVmap("build -q " + Quote(bag) + " -o " + Quote(dir.path() / "cli_map"), &output), 0) << output;

  // Frames held while the builder is busy: the whole bag, so that a slow moment of this shared machine drops none.
  const auto node = StartVmapNode("/teach_test", {"image:=/camera/image_raw", "odom:=/odom", "_teach_queue:=300"},
                                  dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/teach_test/vmap")) << node->Log();
  ros::NodeHandle handle;
  std::mutex mutex;
  vmap_ros::TeachProgress progress;
  const ros::Subscriber subscriber = handle.subscribe<vmap_ros::TeachProgress>(
      "/teach_test/vmap/teach/progress", 1000, [&](const vmap_ros::TeachProgress::ConstPtr& message) {
        std::lock_guard<std::mutex> lock(mutex);
        progress = *message;
      });
  vmap_ros::StartTeach start;
  start.request.map = (dir.path() / "node_map").string();
  ASSERT_TRUE(ros::service::call("/teach_test/vmap/teach/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;
  ASSERT_TRUE(WaitFor([&] { return subscriber.getNumPublishers() > 0; }, kTimeout));

  const auto player = PlayBag(bag, 1.0, dir.path() / "play.log");
  ASSERT_EQ(player->Wait(std::chrono::seconds(300)), 0) << player->Log();
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return progress.frames == stamps.size();
      },
      kTimeout))
      << "frames " << progress.frames << "\n"
      << node->Log();
  EXPECT_EQ(progress.dropped, 0u);
  EXPECT_EQ(progress.skipped, 0u);
  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/teach_test/vmap/teach/stop", stop));
  ASSERT_TRUE(stop.response.success) << stop.response.message;

  // The same key images, links and camera as `vmap build` on the bag.
  const VisualMap cli = ReadMap(dir.path() / "cli_map");
  const VisualMap ros = ReadMap(dir.path() / "node_map");
  ASSERT_EQ(ros.key_images.size(), cli.key_images.size());
  for (size_t i = 0; i < cli.key_images.size(); ++i) {
    EXPECT_EQ(ros.key_images[i].source_index, cli.key_images[i].source_index) << "key image " << i;
    EXPECT_DOUBLE_EQ(ros.key_images[i].timestamp, cli.key_images[i].timestamp) << "key image " << i;
  }
  ASSERT_EQ(ros.links.size(), cli.links.size());
  for (size_t i = 0; i < cli.links.size(); ++i) {
    EXPECT_EQ(ros.links[i].num_verified, cli.links[i].num_verified) << "link " << i;
    EXPECT_EQ(ros.links[i].similarity, cli.links[i].similarity) << "link " << i;
    EXPECT_EQ(ros.links[i].has_pose, cli.links[i].has_pose) << "link " << i;
  }
  // The robot's odometry, beside the map for the repeat runs.
  const std::vector<OdometrySample> odometry = ReadOdometryCsv(dir.path() / "node_map" / "teach_odometry.csv");
  ASSERT_EQ(odometry.size(), stamps.size());
  EXPECT_EQ(odometry.front().timestamp, stamps.front().toSec());
  EXPECT_NEAR(odometry.back().x, 0.05 * (stamps.size() - 1), 1e-12);
  ASSERT_TRUE(ros.input.camera.has_value());
  EXPECT_EQ(ros.input.camera->fx, cli.input.camera->fx);
  EXPECT_EQ(ros.input.path, "/camera/image_raw");
  EXPECT_TRUE(node->Running());
}

// A teach run of the node in namespace `ns` (its parameters `parameters`) into DIR/map, fed a bag of lab_floor's first
// `frames` frames at their recorded rate; returns once the node took every frame, with the node running.
struct PlayedTeach {
  std::unique_ptr<ChildProcess> node;
  std::vector<ros::Time> stamps;
};
void TeachFromPlayedBag(const std::string& ns, const std::vector<std::string>& parameters, const fs::path& dir,
                        int frames, PlayedTeach* played) {
  const fs::path bag = dir / "teach.bag";
  played->stamps =
      WriteVideoBag(fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4", 0, frames - 1, bag, "bgr8", 0.05);
  std::vector<std::string> arguments = {"image:=/camera/image_raw", "odom:=/odom"};
  arguments.insert(arguments.end(), parameters.begin(), parameters.end());
  played->node = StartVmapNode(ns, arguments, dir / "node.log");
  ChildProcess& node = *played->node;
  ASSERT_TRUE(WaitForNodeServices(ns + "/vmap")) << node.Log();
  ros::NodeHandle handle;
  std::mutex mutex;
  uint32_t taken = 0;
  const ros::Subscriber subscriber = handle.subscribe<vmap_ros::TeachProgress>(
      ns + "/vmap/teach/progress", 100, [&](const vmap_ros::TeachProgress::ConstPtr& message) {
        std::lock_guard<std::mutex> lock(mutex);
        taken = message->frames;
      });
  vmap_ros::StartTeach start;
  start.request.map = (dir / "map").string();
  ASSERT_TRUE(ros::service::call(ns + "/vmap/teach/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;
  ASSERT_TRUE(WaitFor([&] { return subscriber.getNumPublishers() > 0; }, kTimeout));
  const auto player = PlayBag(bag, 1.0, dir / "play.log");
  ASSERT_EQ(player->Wait(std::chrono::seconds(120)), 0) << player->Log();
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return taken == played->stamps.size();
      },
      kTimeout))
      << node.Log();
}

// SIGTERM (roslaunch's escalation, systemd's and docker's stop) ends a teach run as SIGINT does: its map is
// written with every frame the node took, not lost with the process.
TEST(TeachNode, ATerminateSignalFinishesTheTeachRunsMap) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_teach_sigterm");
  PlayedTeach played;
  ASSERT_NO_FATAL_FAILURE(TeachFromPlayedBag("/teach_term", {"_teach_queue:=100"}, dir.path(), 30, &played));
  const auto& node = played.node;
  const std::vector<ros::Time>& stamps = played.stamps;

  EXPECT_EQ(node->Stop(std::chrono::seconds(60), SIGTERM), 0) << node->Log();
  const VisualMap map = ReadMap(dir.path() / "map");
  EXPECT_EQ(map.num_frames, static_cast<int>(stamps.size()));
  EXPECT_GE(map.key_images.size(), 2u);
  // As ~teach/stop writes it: the odometry beside the map, and the log says so while ROS is still up to log it.
  EXPECT_TRUE(fs::is_regular_file(dir.path() / "map/teach_odometry.csv")) << node->Log();
  EXPECT_NE(node->Log().find("teach run stopped: map"), std::string::npos) << node->Log();
}

// SIGKILL (or the power) gives the node no time to finish: what is left is the last snapshot, and it holds the
// odometry of its stretch beside its map, for the repeat runs' taught speeds and the localizer's pace.
TEST(TeachNode, AKilledTeachRunLeavesItsLastSnapshotWithItsOdometry) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_teach_sigkill");
  PlayedTeach played;
  ASSERT_NO_FATAL_FAILURE(
      TeachFromPlayedBag("/teach_kill", {"_teach_queue:=100", "_snapshot_every:=0.2"}, dir.path(), 40, &played));
  const auto& node = played.node;
  const std::vector<ros::Time>& stamps = played.stamps;

  node->Stop(std::chrono::seconds(10), SIGKILL);
  const VisualMap map = ReadMap(dir.path() / "map");
  ASSERT_TRUE(map.coverage.has_value());
  EXPECT_EQ(map.coverage->end, CoverageEnd::kSnapshot);
  EXPECT_GE(map.num_frames, 2);
  const std::vector<OdometrySample> odometry = ReadOdometryCsv(dir.path() / "map" / "teach_odometry.csv");
  ASSERT_FALSE(odometry.empty());
  EXPECT_LE(odometry.size(), stamps.size());
  EXPECT_GE(odometry.front().timestamp, stamps.front().toSec());
  EXPECT_LE(odometry.back().timestamp, stamps.back().toSec());
}

// A second teach run into the same map is a new run: its map takes the camera of its own CameraInfo (not the first
// run's, which the node still holds), and keeps no odometry of the first run when it received none itself.
TEST(TeachNode, ASecondTeachRunTakesItsOwnCameraAndNoOdometryOfTheFirst) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_teach_again");
  PlayedTeach played;
  ASSERT_NO_FATAL_FAILURE(TeachFromPlayedBag("/teach_again", {"_teach_queue:=100"}, dir.path(), 20, &played));
  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/teach_again/vmap/teach/stop", stop));
  ASSERT_TRUE(stop.response.success) << stop.response.message;
  ASSERT_TRUE(fs::is_regular_file(dir.path() / "map/teach_odometry.csv"));
  const std::optional<Camera> first_camera = ReadMap(dir.path() / "map").input.camera;
  ASSERT_TRUE(first_camera.has_value());

  ros::NodeHandle handle;
  std::mutex mutex;
  uint32_t taken = 0;
  const ros::Subscriber progress = handle.subscribe<vmap_ros::TeachProgress>(
      "/teach_again/vmap/teach/progress", 100, [&](const vmap_ros::TeachProgress::ConstPtr& message) {
        std::lock_guard<std::mutex> lock(mutex);
        taken = message->frames;
      });
  vmap_ros::StartTeach start;
  start.request.map = (dir.path() / "map").string();
  ASSERT_TRUE(ros::service::call("/teach_again/vmap/teach/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;
  ros::Publisher images = handle.advertise<sensor_msgs::Image>("/camera/image_raw", 100);
  ros::Publisher infos = handle.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 100);
  ASSERT_TRUE(WaitFor(
      [&] {
        return images.getNumSubscribers() > 0 && infos.getNumSubscribers() > 0 && progress.getNumPublishers() > 0;
      },
      kTimeout));
  // Another camera (a longer lens), its CameraInfo with every frame as a driver sends it.
  const double fx = 1.5 * first_camera->fx;
  cv::VideoCapture video((fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4").string());
  constexpr uint32_t kFrames = 12;
  for (uint32_t i = 0; i < kFrames; ++i) {
    cv::Mat pixels;
    ASSERT_TRUE(video.read(pixels));
    sensor_msgs::Image image;
    image.header.stamp = ros::Time(2000.0 + 0.1 * i);
    image.height = pixels.rows;
    image.width = pixels.cols;
    image.encoding = "bgr8";
    image.step = static_cast<uint32_t>(pixels.cols * pixels.elemSize());
    image.data.assign(pixels.data, pixels.data + image.step * image.height);
    sensor_msgs::CameraInfo info;
    info.header = image.header;
    info.width = image.width;
    info.height = image.height;
    info.K = {fx, 0, first_camera->cx, 0, fx, first_camera->cy, 0, 0, 1};
    infos.publish(info);
    images.publish(image);
    ros::Duration(0.05).sleep();
  }
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return taken == kFrames;
      },
      kTimeout))
      << played.node->Log();
  ASSERT_TRUE(ros::service::call("/teach_again/vmap/teach/stop", stop));
  ASSERT_TRUE(stop.response.success) << stop.response.message;
  const VisualMap map = ReadMap(dir.path() / "map");
  EXPECT_EQ(map.num_frames, static_cast<int>(kFrames));
  ASSERT_TRUE(map.input.camera.has_value());
  EXPECT_DOUBLE_EQ(map.input.camera->fx, fx) << "the run's own CameraInfo";
  EXPECT_FALSE(fs::exists(dir.path() / "map/teach_odometry.csv")) << "the first run's odometry";
  EXPECT_EQ(stop.response.message.find("odometry"), std::string::npos) << stop.response.message;
}

// A build that fails during the run (here ~strict and a frame of another size) is said in the log when it happens, not
// first when the run is stopped: from then on the camera's frames go nowhere.
TEST(TeachNode, ARunWhoseBuildFailsSaysSoAtOnce) {
  ScopedTempDir dir("ros_teach_fails");
  const auto node =
      StartVmapNode("/teach_fails", {"image:=/fails/image_raw", "_strict:=true"}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/teach_fails/vmap")) << node->Log();
  vmap_ros::StartTeach start;
  start.request.map = (dir.path() / "map").string();
  ASSERT_TRUE(ros::service::call("/teach_fails/vmap/teach/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;
  ros::NodeHandle handle;
  ros::Publisher images = handle.advertise<sensor_msgs::Image>("/fails/image_raw", 10);
  ASSERT_TRUE(WaitFor([&] { return images.getNumSubscribers() > 0; }, kTimeout));
  for (int i = 0; i < 4; ++i) {
    images.publish(i < 3 ? GreyImage(64, 48, 1.0 + 0.1 * i, 40 * i) : GreyImage(96, 72, 1.0 + 0.1 * i));
    ros::Duration(0.1).sleep();
  }
  EXPECT_TRUE(WaitFor([&] { return node->Log().find("the teach run failed") != std::string::npos; }, kTimeout))
      << node->Log();
  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/teach_fails/vmap/teach/stop", stop));
  EXPECT_FALSE(stop.response.success);
  EXPECT_NE(stop.response.message.find("strict"), std::string::npos) << stop.response.message;
  EXPECT_TRUE(node->Running());
}

// Frames whose stamps go back are taken as they arrive (a live map does not wait for late frames); since `vmap build`
// on a bag of them orders them by stamp, the node says so, once.
TEST(TeachNode, FramesStampedOutOfOrderAreSaidOnce) {
  ScopedTempDir dir("ros_teach_order");
  const auto node = StartVmapNode("/teach_order", {"image:=/order/image_raw"}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/teach_order/vmap")) << node->Log();
  ros::NodeHandle handle;
  uint32_t taken = 0;
  std::mutex mutex;
  const ros::Subscriber progress = handle.subscribe<vmap_ros::TeachProgress>(
      "/teach_order/vmap/teach/progress", 100, [&](const vmap_ros::TeachProgress::ConstPtr& message) {
        std::lock_guard<std::mutex> lock(mutex);
        taken = message->frames;
      });
  vmap_ros::StartTeach start;
  start.request.map = (dir.path() / "map").string();
  ASSERT_TRUE(ros::service::call("/teach_order/vmap/teach/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;
  ros::Publisher images = handle.advertise<sensor_msgs::Image>("/order/image_raw", 10);
  ASSERT_TRUE(WaitFor([&] { return images.getNumSubscribers() > 0 && progress.getNumPublishers() > 0; }, kTimeout));
  const std::vector<double> stamps = {2.0, 1.0, 3.0, 2.5};
  for (size_t i = 0; i < stamps.size(); ++i) {
    images.publish(GreyImage(64, 48, stamps[i], static_cast<uint8_t>(50 * i)));
    ros::Duration(0.1).sleep();
  }
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return taken == stamps.size();
      },
      kTimeout))
      << node->Log();
  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/teach_order/vmap/teach/stop", stop));
  const std::string log = node->Log();
  const size_t said = log.find("before the frame before it");
  ASSERT_NE(said, std::string::npos) << log;
  EXPECT_EQ(log.find("before the frame before it", said + 1), std::string::npos) << "once: " << log;
}

TEST(TeachNode, RefusesAFolderThatIsNotAMapAndLeavesItAsItWas) {
  ScopedTempDir dir("ros_teach_refuse");
  fs::create_directories(dir.path() / "notes");
  std::ofstream(dir.path() / "notes" / "todo.txt") << "my notes\n";
  const auto node = StartVmapNode("/teach_refuse", {}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/teach_refuse/vmap")) << node->Log();
  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/teach_refuse/vmap/teach/stop", stop));
  EXPECT_FALSE(stop.response.success);
  EXPECT_NE(stop.response.message.find("no teach run is in progress"), std::string::npos) << stop.response.message;
  vmap_ros::StartTeach start;
  start.request.map = (dir.path() / "notes").string();
  ASSERT_TRUE(ros::service::call("/teach_refuse/vmap/teach/start", start));
  EXPECT_FALSE(start.response.success);
  EXPECT_NE(start.response.message.find("notes"), std::string::npos) << start.response.message;
  EXPECT_EQ(testing::ReadText(dir.path() / "notes" / "todo.txt"), "my notes\n");
  EXPECT_TRUE(fs::exists(dir.path() / "notes" / "todo.txt"));
  // A bad parameter is named.
  ros::param::set("/teach_refuse/vmap/tau", "high");
  start.request.map = (dir.path() / "map").string();
  ASSERT_TRUE(ros::service::call("/teach_refuse/vmap/teach/start", start));
  EXPECT_FALSE(start.response.success);
  EXPECT_NE(start.response.message.find("~tau"), std::string::npos) << start.response.message;
  EXPECT_FALSE(fs::exists(dir.path() / "map"));
  EXPECT_TRUE(node->Running());
}

// A camera that sends broken frames is said once in a while with the count, not a warning a frame; a teach run that got
// no CameraInfo says at its stop that the map has no camera (a repeat run on it needs ~focal_px), not first at the
// repeat's start.
TEST(TeachNode, SkippedFramesAreSaidOnceInAWhileAndAMapWithoutACameraAtTheStop) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_teach_skips");
  const fs::path bag = dir.path() / "teach.bag";
  const std::vector<ros::Time> stamps =
      WriteVideoBag(fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4", 0, 29, bag, "bgr8");
  const auto node =
      StartVmapNode("/teach_skips", {"image:=/camera/image_raw", "camera_info:=/no_camera_info", "_teach_queue:=100"},
                    dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/teach_skips/vmap")) << node->Log();
  ros::NodeHandle handle;
  std::mutex mutex;
  vmap_ros::TeachProgress progress;
  const ros::Subscriber subscriber = handle.subscribe<vmap_ros::TeachProgress>(
      "/teach_skips/vmap/teach/progress", 100, [&](const vmap_ros::TeachProgress::ConstPtr& message) {
        std::lock_guard<std::mutex> lock(mutex);
        progress = *message;
      });
  vmap_ros::StartTeach start;
  start.request.map = (dir.path() / "map").string();
  ASSERT_TRUE(ros::service::call("/teach_skips/vmap/teach/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;
  ros::Publisher images = handle.advertise<sensor_msgs::Image>("/camera/image_raw", 100);
  ASSERT_TRUE(WaitFor([&] { return images.getNumSubscribers() > 0 && subscriber.getNumPublishers() > 0; }, kTimeout));
  constexpr int kBroken = 20;
  for (int i = 0; i < kBroken; ++i) {
    sensor_msgs::Image broken;
    broken.header.stamp = ros::Time(1.0 + 0.01 * i);
    broken.width = 64;
    broken.height = 48;
    broken.encoding = "mono8";
    broken.step = 64;
    broken.data.resize(100);  // 64 x 48 pixels need 3072 bytes
    images.publish(broken);
  }
  // The bag's camera_info goes to this process, not the node: rosbag play waits for a subscriber of every topic.
  const ros::Subscriber camera_info_sink = handle.subscribe<sensor_msgs::CameraInfo>(
      "/camera/camera_info", 100, [&](const sensor_msgs::CameraInfo::ConstPtr&) {});
  const auto player = PlayBag(bag, 1.0, dir.path() / "play.log");
  ASSERT_EQ(player->Wait(std::chrono::seconds(120)), 0) << player->Log();
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return progress.frames == stamps.size() && progress.skipped == static_cast<uint32_t>(kBroken);
      },
      kTimeout))
      << "frames " << progress.frames << ", skipped " << progress.skipped << "\n"
      << node->Log();
  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/teach_skips/vmap/teach/stop", stop));
  ASSERT_TRUE(stop.response.success) << stop.response.message;
  EXPECT_NE(stop.response.message.find("the map has no camera (no CameraInfo came on /no_camera_info"),
            std::string::npos)
      << stop.response.message;
  // The broken frames came within a second: said once, with the count so far.
  const std::string log = node->Log();
  size_t said = 0;
  for (size_t at = log.find("skipping it"); at != std::string::npos; at = log.find("skipping it", at + 1)) ++said;
  EXPECT_EQ(said, 1u) << log;
  EXPECT_NE(log.find("skipping it (1 frame skipped so far)"), std::string::npos) << log;
}

}  // namespace
}  // namespace vmap::ros_testing
