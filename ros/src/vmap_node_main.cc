// vmap_node: teach and repeat on a robot (docs/ros.md). `rosrun vmap_ros vmap_node image:=/camera/image_raw`, or
// the launch files in ros/launch.

#include <ros/ros.h>

#include "vmap/core/runtime.h"

#include "vmap_ros/rosconsole_sink.h"
#include "vmap_ros/terminate_signal.h"
#include "vmap_ros/vmap_node.h"

int main(int argc, char** argv) {
  // First, while this is the only thread (core/runtime.h). A signal asks the node to stop (terminate_signal.h): a
  // run in progress is ended by the node, not by vmap's handler nor roscpp's.
  vmap::RuntimeOptions runtime;
  runtime.handle_interrupts = false;
  vmap::InitializeRuntime(runtime);
  ros::init(argc, argv, "vmap", ros::init_options::NoSigintHandler);
  vmap::ros_node::LogThroughRosconsole();
  vmap::ros_node::StopOnSignals();
  if (!vmap::ros_node::WaitForMaster()) return 128 + vmap::ros_node::StopSignal();
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  vmap::ros_node::VmapNode vmap_node(node, private_node);
  vmap::ros_node::StopOnShutdownRequests([&vmap_node] { vmap_node.HaltRobot(); });
  // Services that take seconds (a map loading, a teach run finishing) keep one thread; the camera has another.
  ros::AsyncSpinner spinner(3);
  spinner.start();
  vmap::ros_node::WaitForStop();
  // While ROS is up: the robot's last command a stop, a teach run's map written, and both said in the log.
  const bool finished = vmap_node.Stop();
  spinner.stop();
  ros::shutdown();
  return finished ? 0 : 1;
}
