// The node's repeat run on a real ROS master: a bag made from a shared video is played to it, and what it publishes
// is checked against `vmap localize` on the same frames.

#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <std_msgs/Bool.h>
#include <std_srvs/Trigger.h>

#include "vmap/sources/odometry.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

#include "ros_harness.h"
#include "vmap_ros/Localization.h"
#include "vmap_ros/StartRepeat.h"

namespace vmap::ros_testing {
namespace {

namespace fs = std::filesystem;
using testing::Quote;
using testing::RunVmap;
using testing::ScopedTempDir;
using testing::SharedDir;

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// The rows of a CSV written by `vmap localize`, each by its column names.
std::vector<std::map<std::string, std::string>> ReadCsv(const fs::path& file) {
  std::stringstream text(testing::ReadText(file));
  std::string line;
  std::getline(text, line);
  const std::vector<std::string> header = SplitCsvLine(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(text, line)) {
    const std::vector<std::string> fields = SplitCsvLine(line);
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < header.size() && i < fields.size(); ++i) row[header[i]] = fields[i];
    rows.push_back(row);
  }
  return rows;
}

std::string Number(double value) { return std::isfinite(value) ? fmt::format("{:.6g}", value) : std::string(); }

// Collects what the node publishes.
struct Published {
  std::mutex mutex;
  std::vector<vmap_ros::Localization> localizations;
  std::vector<bool> localized;
  std::vector<geometry_msgs::Twist> commands;

  void OnLocalization(const vmap_ros::Localization::ConstPtr& message) {
    std::lock_guard<std::mutex> lock(mutex);
    localizations.push_back(*message);
  }
  void OnCommand(const geometry_msgs::Twist::ConstPtr& message) {
    std::lock_guard<std::mutex> lock(mutex);
    commands.push_back(*message);
  }
  void OnLocalized(const std_msgs::Bool::ConstPtr& message) {
    std::lock_guard<std::mutex> lock(mutex);
    localized.push_back(message->data);
  }
  bool HasStamp(const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex);
    return !localizations.empty() && localizations.back().header.stamp == stamp;
  }
};

// The robot has odometry in both runs (the teach run's beside the map, as the teach node writes it; `odom` in the
// repeat): the node paces the belief by the distance driven as `vmap localize` does on the bag's odometry.
TEST(RepeatNode, LocalizesThePlayedFramesAsVmapLocalizeDoes) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_repeat");
  const fs::path video = fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4";
  const fs::path teach = dir.path() / "teach.bag", repeat = dir.path() / "repeat.bag", map = dir.path() / "map";
  WriteVideoBag(video, 0, 199, teach, "bgr8", 0.05);
  const std::vector<ros::Time> stamps = WriteVideoBag(video, 20, 139, repeat, "bgr8", 0.05);
  std::string output;
  ASSERT_EQ(RunVmap("build -q " + Quote(teach) + " -o " + Quote(map), &output), 0) << output;
  std::ofstream(map / "teach_odometry.csv") << OdometryCsv(ReadOdometry(teach.string(), ""));

  const auto node = StartVmapNode("/repeat_test", {"image:=/camera/image_raw", "odom:=/odom"}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/repeat_test/vmap")) << node->Log();
  ros::NodeHandle handle;
  Published published;
  const ros::Subscriber localizations =
      handle.subscribe("/repeat_test/vmap/localization", 1000, &Published::OnLocalization, &published);
  const ros::Subscriber localized =
      handle.subscribe("/repeat_test/vmap/localized", 10, &Published::OnLocalized, &published);
  const ros::Subscriber commands = handle.subscribe("/repeat_test/cmd_vel", 1000, &Published::OnCommand, &published);

  ASSERT_TRUE(WaitFor([&] { return localized.getNumPublishers() > 0 && commands.getNumPublishers() > 0; },
                      std::chrono::seconds(60)));
  vmap_ros::StartRepeat start;
  start.request.map = map.string();
  start.request.goal = -1;
  start.request.start = -1;
  ASSERT_TRUE(ros::service::call("/repeat_test/vmap/repeat/start", start)) << node->Log();
  ASSERT_TRUE(start.response.success) << start.response.message;
  EXPECT_NE(start.response.message.find("teach odometry"), std::string::npos) << start.response.message;
  ASSERT_FALSE(start.response.route.empty());
  EXPECT_EQ(start.response.route.front(), 0);
  // Our subscription is connected before the first frame is played.
  ASSERT_TRUE(WaitFor([&] { return localizations.getNumPublishers() > 0; }, std::chrono::seconds(60)));

  const auto player = PlayBag(repeat, 1.0, dir.path() / "play.log");
  ASSERT_EQ(player->Wait(std::chrono::seconds(180)), 0) << player->Log();
  // Drop, do not lag: the newest frame is always processed, however many were dropped before it.
  ASSERT_TRUE(WaitFor([&] { return published.HasStamp(stamps.back()); }, std::chrono::seconds(60))) << node->Log();

  // A command for every frame processed, published before its localization message (and so received before it).
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(published.mutex);
        return published.commands.size() >= published.localizations.size();
      },
      std::chrono::seconds(60)));
  std::vector<vmap_ros::Localization> messages;
  {
    std::lock_guard<std::mutex> lock(published.mutex);
    messages = published.localizations;
    EXPECT_EQ(published.commands.size(), messages.size());
    int following = 0;
    for (size_t k = 0; k < messages.size() && k < published.commands.size(); ++k) {
      EXPECT_EQ(published.commands[k].linear.x, messages[k].command.linear.x) << "frame " << k;
      EXPECT_EQ(published.commands[k].angular.z, messages[k].command.angular.z) << "frame " << k;
      EXPECT_TRUE(std::isfinite(messages[k].command.linear.x) && std::isfinite(messages[k].command.angular.z));
      following += messages[k].controller_state == "following" && messages[k].command.linear.x > 0.0;
    }
    // The frames are the map's route: once localized the robot drives along it.
    EXPECT_GT(following, static_cast<int>(messages.size()) / 2);
    ASSERT_FALSE(published.localized.empty());
    EXPECT_FALSE(published.localized.front());  // latched false at the start, then true once localized
    EXPECT_TRUE(published.localized.back());
  }
  // Every played frame is either processed or counted as dropped, in order.
  size_t dropped = 0;
  std::vector<ros::Time> processed;
  for (const vmap_ros::Localization& message : messages) {
    dropped += message.frames_dropped;
    if (!processed.empty()) {
      EXPECT_LT(processed.back(), message.header.stamp);
    }
    processed.push_back(message.header.stamp);
    EXPECT_EQ(message.header.frame_id, "camera");
    EXPECT_GE(message.latency, 0.0);
  }
  EXPECT_EQ(processed.size() + dropped, stamps.size());
  RecordProperty("frames", static_cast<int>(stamps.size()));
  RecordProperty("processed", static_cast<int>(processed.size()));

  // `vmap localize` on the frames the node processed.
  WriteBagSubset(repeat, processed, dir.path() / "processed.bag");
  ASSERT_EQ(RunVmap("localize -q " + Quote(map) + " " + Quote(dir.path() / "processed.bag") + " --csv " +
                        Quote(dir.path() / "cli.csv") + " --json " + Quote(dir.path() / "cli.json"),
                    &output),
            0)
      << output;
  const auto rows = ReadCsv(dir.path() / "cli.csv");
  ASSERT_EQ(rows.size(), messages.size());
  const nlohmann::json cli_run = nlohmann::json::parse(testing::ReadText(dir.path() / "cli.json"));
  ASSERT_EQ(cli_run.at("frames").size(), messages.size());
  int paced_on = 0;
  int localized_frames = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    const vmap_ros::Localization& message = messages[i];
    SCOPED_TRACE("frame " + std::to_string(i) + " stamp " + row.at("timestamp"));
    EXPECT_EQ(fmt::format("{:.6f}", message.header.stamp.toSec()), row.at("timestamp"));
    EXPECT_EQ(message.status_name, row.at("status"));
    EXPECT_EQ(std::to_string(message.key), row.at("key"));
    EXPECT_EQ(std::to_string(message.next_key), row.at("next_key"));
    EXPECT_EQ(std::to_string(message.verified_key), row.at("verified"));
    EXPECT_EQ(std::to_string(message.verified_next), row.at("next_verified"));
    EXPECT_EQ(Number(message.heading_px), row.at("heading_px"));
    EXPECT_EQ(Number(message.heading_deg), row.at("heading_deg"));
    EXPECT_EQ(Number(message.progress), row.at("progress"));
    EXPECT_EQ(message.translation_known ? "1" : "0", row.at("translation_known"));
    EXPECT_EQ(message.guidance, row.at("guidance"));
    EXPECT_EQ(message.motion_steps, cli_run.at("frames")[i].at("motion_steps").get<int>());
    paced_on += message.motion_steps > 1;
    if (message.pose_valid) {
      EXPECT_EQ(fmt::format("{:.9g}", message.pose.position.x), row.at("tx"));
    }
    localized_frames += message.status != vmap_ros::Localization::LOST;
  }
  // The frames are the map's own place: most localize.
  EXPECT_GT(localized_frames, static_cast<int>(rows.size()) * 9 / 10);
  RecordProperty("frames_paced_on", paced_on);

  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/repeat_test/vmap/repeat/stop", stop));
  EXPECT_TRUE(stop.response.success) << stop.response.message;
  EXPECT_TRUE(node->Running());
}

// Spins this process's callbacks for `seconds`.
void SpinFor(double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    ros::spinOnce();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// The robot never keeps a command the node no longer stands behind: a pause stops it after the frame in progress
// (whose command once came after the pause's stop), a camera gone quiet stops it after ~camera_timeout, and so does
// the node's own end (whose stop once came after ROS was down, or never).
TEST(RepeatNode, APauseAQuietCameraAndTheNodesEndStopTheRobot) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_repeat_stops");
  const fs::path video = fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4";
  const fs::path teach = dir.path() / "teach.bag", map = dir.path() / "map";
  // Two stretches of the route, the second after the first: the robot drives on in each (no odometry, which would
  // start again from zero in the second).
  const fs::path first = dir.path() / "first.bag", second = dir.path() / "second.bag";
  WriteVideoBag(video, 0, 199, teach, "bgr8", 0.05);
  WriteVideoBag(video, 20, 119, first, "bgr8", 0.0);
  WriteVideoBag(video, 120, 179, second, "bgr8", 0.0);
  std::string output;
  ASSERT_EQ(RunVmap("build -q " + Quote(teach) + " -o " + Quote(map), &output), 0) << output;

  const auto node = StartVmapNode("/stops", {"image:=/camera/image_raw", "odom:=/odom", "_camera_timeout:=0.5"},
                                  dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/stops/vmap")) << node->Log();
  ros::NodeHandle handle;
  Published published;
  const ros::Subscriber commands = handle.subscribe("/stops/cmd_vel", 1000, &Published::OnCommand, &published);
  ASSERT_TRUE(WaitFor([&] { return commands.getNumPublishers() > 0; }, std::chrono::seconds(60)));
  const auto count = [&] {
    std::lock_guard<std::mutex> lock(published.mutex);
    return published.commands.size();
  };
  const auto moving_since = [&](size_t first) {
    std::lock_guard<std::mutex> lock(published.mutex);
    for (size_t i = first; i < published.commands.size(); ++i) {
      if (published.commands[i].linear.x != 0.0) return true;
    }
    return false;
  };
  const auto last_is_stop = [&] {
    std::lock_guard<std::mutex> lock(published.mutex);
    return !published.commands.empty() && published.commands.back().linear.x == 0.0 &&
           published.commands.back().angular.z == 0.0;
  };
  vmap_ros::StartRepeat start;
  start.request.map = map.string();
  start.request.goal = -1;
  start.request.start = -1;
  ASSERT_TRUE(ros::service::call("/stops/vmap/repeat/start", start)) << node->Log();
  ASSERT_TRUE(start.response.success) << start.response.message;

  // 1. Pauses while frames come: once a pause has answered, the robot's last command is a stop and stays one.
  auto player = PlayBag(first, 1.0, dir.path() / "play.log");
  ASSERT_TRUE(WaitFor([&] { return moving_since(0); }, std::chrono::seconds(60))) << node->Log();
  for (int i = 0; i < 4 && player->Running(); ++i) {
    std_srvs::Trigger pause, resume;
    ASSERT_TRUE(ros::service::call("/stops/vmap/repeat/pause", pause));
    ASSERT_TRUE(pause.response.success) << pause.response.message;
    SpinFor(0.3);
    EXPECT_TRUE(last_is_stop()) << "pause " << i;
    const size_t before = count();
    ASSERT_TRUE(ros::service::call("/stops/vmap/repeat/resume", resume));
    ASSERT_TRUE(resume.response.success) << resume.response.message;
    WaitFor([&] { return moving_since(before) || !player->Running(); }, std::chrono::seconds(30));
  }
  ASSERT_EQ(player->Wait(std::chrono::seconds(120)), 0) << player->Log();
  const size_t logged = node->Log().size();

  // 2. The camera goes quiet: stopped after ~camera_timeout, said in the log.
  EXPECT_TRUE(WaitFor(last_is_stop, std::chrono::seconds(10))) << node->Log();
  EXPECT_TRUE(WaitFor([&] { return node->Log().find("no camera frame on", logged) != std::string::npos; },
                      std::chrono::seconds(10)))
      << node->Log();

  // 3. Frames again, the robot drives; the node is stopped (SIGINT): its last command is a stop.
  const size_t before = count();
  player = PlayBag(second, 1.0, dir.path() / "play2.log");
  ASSERT_TRUE(WaitFor([&] { return moving_since(before); }, std::chrono::seconds(60))) << node->Log();
  {
    // The controller was told of the stop: the first command after it starts from rest, as a first command does
    // (it was the cruise speed again at once).
    std::lock_guard<std::mutex> lock(published.mutex);
    EXPECT_EQ(published.commands[before].linear.x, 0.0) << node->Log();
  }
  EXPECT_EQ(node->Stop(std::chrono::seconds(30), SIGINT), 0) << node->Log();
  SpinFor(0.5);
  EXPECT_TRUE(last_is_stop()) << node->Log();
  EXPECT_NE(node->Log().find("the robot is stopped"), std::string::npos) << node->Log();
}

// A run stopped is no longer localized (the latched ~localized says so to a subscriber that comes later); and a node
// the master shuts down (another node started under its name: two launch files) stops its robot before it goes, where
// roscpp's own answer had left the robot on its last command.
TEST(RepeatNode, ARunStoppedIsNotLocalizedAndANodeTheMasterShutsDownStopsItsRobot) {
  SKIP_WITHOUT_SHARED();
  ScopedTempDir dir("ros_repeat_clash");
  const fs::path video = fs::path(SharedDir()) / "data/lab_floor/lab_floor.mp4";
  const fs::path teach = dir.path() / "teach.bag", map = dir.path() / "map", repeat = dir.path() / "repeat.bag";
  WriteVideoBag(video, 0, 199, teach, "bgr8", 0.05);
  WriteVideoBag(video, 20, 139, repeat, "bgr8", 0.0);
  std::string output;
  ASSERT_EQ(RunVmap("build -q " + Quote(teach) + " -o " + Quote(map), &output), 0) << output;

  const auto node = StartVmapNode("/clash", {"image:=/camera/image_raw", "odom:=/odom"}, dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/clash/vmap")) << node->Log();
  ros::NodeHandle handle;
  Published published;
  const ros::Subscriber commands = handle.subscribe("/clash/cmd_vel", 1000, &Published::OnCommand, &published);
  ASSERT_TRUE(WaitFor([&] { return commands.getNumPublishers() > 0; }, std::chrono::seconds(60)));
  const auto moving = [&] {
    std::lock_guard<std::mutex> lock(published.mutex);
    return !published.commands.empty() && published.commands.back().linear.x != 0.0;
  };
  const auto start_and_drive = [&] {
    vmap_ros::StartRepeat start;
    start.request.map = map.string();
    start.request.goal = -1;
    start.request.start = -1;
    ASSERT_TRUE(ros::service::call("/clash/vmap/repeat/start", start)) << node->Log();
    ASSERT_TRUE(start.response.success) << start.response.message;
    auto player = PlayBag(repeat, 1.0, dir.path() / "play.log");
    ASSERT_TRUE(WaitFor(moving, std::chrono::seconds(60))) << node->Log();
    player->Stop(std::chrono::seconds(5));
  };

  // 1. Localized, then stopped: a subscriber that comes after the stop reads false.
  start_and_drive();
  std_srvs::Trigger stop;
  ASSERT_TRUE(ros::service::call("/clash/vmap/repeat/stop", stop));
  ASSERT_TRUE(stop.response.success) << stop.response.message;
  Published later;
  const ros::Subscriber localized = handle.subscribe("/clash/vmap/localized", 10, &Published::OnLocalized, &later);
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(later.mutex);
        return !later.localized.empty();
      },
      std::chrono::seconds(10)));
  {
    std::lock_guard<std::mutex> lock(later.mutex);
    EXPECT_FALSE(later.localized.back()) << "a run stopped read as localized";
  }

  // 2. Driving again; a second node under the same name: the first one publishes a stop at once and exits. Whether
  // the stop reaches a subscriber is a race with the master's update that drops the first node's connections (lost
  // under a loaded machine), so the node's own account is checked, not the topic.
  start_and_drive();
  const auto second = StartVmapNode("/clash", {}, dir.path() / "second.log");
  EXPECT_EQ(node->Wait(std::chrono::seconds(60)), 0) << node->Log();
  EXPECT_NE(node->Log().find("the ROS master asks this node to shut down"), std::string::npos) << node->Log();
  EXPECT_NE(node->Log().find("the robot is stopped"), std::string::npos) << node->Log();
}

}  // namespace
}  // namespace vmap::ros_testing
