// The closed loop through ROS: vmap's simulator as a node (camera, odometry and motors on topics) driven by a vmap
// node on a real master reaches the goal as the same trial run in process does.

#include <fstream>

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sensor_msgs/Image.h>
#include <std_msgs/Bool.h>

#include "vmap/testing/scoped_temp_dir.h"

#include "ros_harness.h"
#include "vmap_ros/Localization.h"
#include "vmap_ros/StartRepeat.h"

namespace vmap::ros_testing {
namespace {

namespace fs = std::filesystem;
using testing::ScopedTempDir;

TEST(ClosedLoopNode, ASimulatedRobotDrivenThroughRosReachesTheGoalAsInProcess) {
  ScopedTempDir dir("ros_closed_loop");
  // drive's closed-loop test route: 6 m straight; trial 0 of seed 3 starts off the path.
  std::ofstream(dir.path() / "route.csv") << "x,y\n0,0\n6,0\n";
  const std::string simulation = "_route:=" + (dir.path() / "route.csv").string();
  RosMaster::Get();
  ChildProcess simulator(
      {SimulatorBinary().string(), "__ns:=/loop_robot", "__name:=simulator", "localization:=/loop/vmap/localization",
       simulation, "_seed:=3", "_teach_speed:=0.4", "_trial:=0", "_map:=" + (dir.path() / "map").string(),
       "_result:=" + (dir.path() / "result.json").string()},
      dir.path() / "simulator.log");
  // The teach odometry the simulator writes beside the map gives the node the taught profile `vmap simulate` uses.
  const auto node = StartVmapNode("/loop",
                                  {"image:=/loop_robot/camera/image_raw", "odom:=/loop_robot/odom",
                                   "cmd_vel:=/loop_robot/cmd_vel", "_odom_wait:=5"},
                                  dir.path() / "node.log");
  ASSERT_TRUE(WaitForNodeServices("/loop/vmap")) << node->Log();

  // The simulator teaches the route and writes the map (and runs the trial in process) before it says so.
  ros::NodeHandle handle;
  bool ready = false;
  const ros::Subscriber subscriber = handle.subscribe<std_msgs::Bool>(
      "/loop_robot/simulator/ready", 1, [&](const std_msgs::Bool::ConstPtr& message) { ready = message->data; });
  ASSERT_TRUE(WaitFor([&] { return ready || !simulator.Running(); }, std::chrono::seconds(300)));
  ASSERT_TRUE(ready) << simulator.Log();

  vmap_ros::StartRepeat start;
  start.request.map = (dir.path() / "map").string();
  start.request.goal = -1;
  start.request.start = -1;
  ASSERT_TRUE(ros::service::call("/loop/vmap/repeat/start", start)) << node->Log();
  ASSERT_TRUE(start.response.success) << start.response.message;
  EXPECT_NE(start.response.message.find("teach odometry"), std::string::npos) << start.response.message;

  ASSERT_EQ(simulator.Wait(std::chrono::seconds(600)), 0) << simulator.Log() << node->Log();
  nlohmann::json result;
  std::ifstream(dir.path() / "result.json") >> result;
  const nlohmann::json& ros = result.at("ros");
  const nlohmann::json& in_process = result.at("in_process");
  SCOPED_TRACE(result.dump(2));
  RecordProperty("ros", ros.dump());
  RecordProperty("in_process", in_process.dump());
  EXPECT_EQ(in_process.at("end"), "reached goal");
  EXPECT_TRUE(in_process.at("success").get<bool>());
  EXPECT_EQ(ros.at("end"), "reached goal");
  EXPECT_TRUE(ros.at("success").get<bool>());
  // The same trial (start, noise, frames, map, taught profile) with the same brain: the same drive, each frame with
  // the odometry of its time (~odom_wait) and the command answered to it, up to the rounding of stamps and poses in
  // the messages (measured: 0.0103452 m from the goal both, 202 frames both). Without ~odom_wait a frame could read the
  // odometry before its own: one of three runs ended 0.022 m from the goal.
  EXPECT_NEAR(ros.at("final_error").get<double>(), in_process.at("final_error").get<double>(), 1e-6);
  EXPECT_EQ(ros.at("frames").get<int>(), in_process.at("frames").get<int>());
  EXPECT_LE(ros.at("lateral_rms_second_half").get<double>(), 0.1);
  EXPECT_GT(std::abs(ros.at("start_lateral").get<double>()), 0.05);  // it started off the path
  EXPECT_TRUE(node->Running());
}

// The simulator drives each frame by the vmap node's answer to it, paired by stamp (docs/ros.md): this test is the
// vmap node, answering frame k < 10 with 0.3 m/s (k even) or 0.1 m/s (k odd) and the goal at frame 10, after a stop
// on cmd_vel before the first frame (as a node publishes between frames), and without a cmd_vel message for frame 5
// (as a paused node's frame). Paired by count, frame 5 was driven by frame 4's command.
TEST(ClosedLoopNode, EachFrameIsDrivenByTheCommandAnsweredToIt) {
  ScopedTempDir dir("ros_paired");
  std::ofstream(dir.path() / "route.csv") << "x,y\n0,0\n4,0\n";
  RosMaster::Get();
  ros::NodeHandle handle;
  ros::Publisher localization = handle.advertise<vmap_ros::Localization>("/paired/localization", 100);
  ros::Publisher cmd_vel = handle.advertise<geometry_msgs::Twist>("/paired_robot/cmd_vel", 100);
  int frames = 0;
  const ros::Subscriber camera = handle.subscribe<sensor_msgs::Image>(
      "/paired_robot/camera/image_raw", 10, [&](const sensor_msgs::Image::ConstPtr& image) {
        const int k = frames++;
        if (k == 0) cmd_vel.publish(geometry_msgs::Twist());
        vmap_ros::Localization answer;
        answer.header.stamp = image->header.stamp;
        answer.status = vmap_ros::Localization::TRACKING;
        answer.status_name = "tracking";
        answer.key = 0;
        answer.next_key = 1;
        answer.localized = true;
        answer.controller_state = k < 10 ? "following" : "reached goal";
        answer.command.linear.x = k < 10 ? (k % 2 == 0 ? 0.3 : 0.1) : 0.0;
        if (k != 5) cmd_vel.publish(answer.command);
        localization.publish(answer);
      });
  ChildProcess simulator(
      {SimulatorBinary().string(), "__ns:=/paired_robot", "__name:=simulator", "localization:=/paired/localization",
       "_route:=" + (dir.path() / "route.csv").string(), "_lateral_offset:=0", "_heading_offset:=0", "_speed_noise:=0",
       "_turn_noise:=0", "_answer_timeout:=10", "_map:=" + (dir.path() / "map").string(),
       "_result:=" + (dir.path() / "result.json").string()},
      dir.path() / "simulator.log");
  ASSERT_TRUE(WaitFor([&] { return !simulator.Running(); }, std::chrono::seconds(600))) << simulator.Log();
  ASSERT_EQ(simulator.Wait(std::chrono::seconds(10)), 0) << simulator.Log();
  nlohmann::json result;
  std::ifstream(dir.path() / "result.json") >> result;
  const nlohmann::json& ros = result.at("ros");
  SCOPED_TRACE(result.dump(2));
  EXPECT_EQ(ros.at("end"), "reached goal");
  EXPECT_EQ(ros.at("frames"), 11);
  // Ten steps of 0.1 s, five at 0.3 m/s and five at 0.1 m/s, from the route's start 4 m from its goal, exactly (no
  // noise, no start offset).
  EXPECT_NEAR(ros.at("final_error").get<double>(), 4.0 - 0.1 * (5 * 0.3 + 5 * 0.1), 1e-3);
}

// The simulator node checks what it will write before it teaches (its result and map may not land on what it reads,
// nor on each other), and a signal stops it in its teach run, promptly and with a shell's status.
TEST(ClosedLoopNode, TheSimulatorRefusesOutputsOverItsInputsAndStopsOnASignal) {
  ScopedTempDir dir("ros_simulator_refusals");
  RosMaster::Get();
  std::ofstream(dir.path() / "route.csv") << "x,y\n0,0\n6,0\n";
  const std::string route = (dir.path() / "route.csv").string(), map = (dir.path() / "map").string();
  fs::create_directory(dir.path() / "textures");
  struct Case {
    std::vector<std::string> parameters;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{"_route:=" + route, "_map:=" + map, "_result:=" + route}, "~result '" + route + "' would overwrite"},
      {{"_route:=" + route, "_map:=" + map, "_result:=" + map + "/map.json"}, "~result"},
      {{"_route:=" + route, "_map:=" + (dir.path() / "textures").string(),
        "_teach_textures:=" + (dir.path() / "textures").string()},
       "is or holds the input"},
      {{"_route:=" + route, "_map:=" + dir.path().string()}, "is or holds the input"},
      {{"_route:=" + route, "_map:=" + map, "_answer_timeout:=nan"}, "~answer_timeout"},
      {{"_route:=" + route, "_map:=" + map, "_trial:=1.5"}, "~trial"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    // A namespace each: the master keeps a node's private parameters after it exits.
    std::vector<std::string> arguments = {SimulatorBinary().string(), "__ns:=/refusals" + std::to_string(i),
                                          "__name:=simulator"};
    arguments.insert(arguments.end(), c.parameters.begin(), c.parameters.end());
    ChildProcess simulator(arguments, dir.path() / ("simulator" + std::to_string(i) + ".log"));
    EXPECT_EQ(simulator.Wait(std::chrono::seconds(60)), 2) << simulator.Log();
    EXPECT_NE(simulator.Log().find(c.expected), std::string::npos) << c.expected << "\n" << simulator.Log();
    EXPECT_EQ(simulator.Log().find("teaching route"), std::string::npos) << simulator.Log();  // refused first
  }
  EXPECT_FALSE(fs::exists(map));
  EXPECT_EQ(testing::ReadText(dir.path() / "route.csv"), "x,y\n0,0\n6,0\n");

  // A texture folder that holds no image is named as the node's parameter, not as `vmap simulate`'s flag.
  const fs::path notes = dir.path() / "notes";
  fs::create_directory(notes);
  std::ofstream(notes / "notes.txt") << "not an image";
  ChildProcess textured({SimulatorBinary().string(), "__ns:=/refused_textures", "__name:=simulator", "_route:=" + route,
                         "_map:=" + map, "_teach_textures:=" + notes.string()},
                        dir.path() / "textures.log");
  EXPECT_EQ(textured.Wait(std::chrono::seconds(60)), 2) << textured.Log();
  EXPECT_NE(textured.Log().find("~teach_textures '" + notes.string() + "': 'notes.txt' cannot be decoded"),
            std::string::npos)
      << textured.Log();
  EXPECT_EQ(textured.Log().find("--teach-textures"), std::string::npos) << textured.Log();
  EXPECT_FALSE(fs::exists(map));

  // SIGINT in the teach run: out within seconds, status 130, no map.
  ChildProcess simulator({SimulatorBinary().string(), "__ns:=/interrupted", "__name:=simulator", "_route:=loop",
                          "_map:=" + map, "_result:=" + (dir.path() / "result.json").string()},
                         dir.path() / "interrupted.log");
  // The teach run has begun once its map's hidden folder is there (the log's lines wait in stdout's buffer).
  const auto teaching = [&] {
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      if (entry.path().filename().string().rfind(".map.partial-", 0) == 0) return true;
    }
    return false;
  };
  ASSERT_TRUE(WaitFor(teaching, std::chrono::seconds(60))) << simulator.Log();
  EXPECT_EQ(simulator.Stop(std::chrono::seconds(10), SIGINT), 130) << simulator.Log();
  EXPECT_FALSE(fs::exists(map));
  EXPECT_FALSE(fs::exists(dir.path() / "result.json"));
}

}  // namespace
}  // namespace vmap::ros_testing
