// vmap_simulator: vmap's closed-loop simulator as a ROS node (vmap_ros/simulator_node.h, docs/ros.md): the camera,
// odometry and motors of a simulated robot on ROS topics, for a vmap node to drive.

#include <ros/ros.h>

#include "vmap/core/runtime.h"

#include "vmap_ros/rosconsole_sink.h"
#include "vmap_ros/simulator_node.h"
#include "vmap_ros/terminate_signal.h"

int main(int argc, char** argv) {
  vmap::RuntimeOptions runtime;
  runtime.handle_interrupts = false;  // a signal asks the node to stop (terminate_signal.h)
  vmap::InitializeRuntime(runtime);
  ros::init(argc, argv, "vmap_simulator", ros::init_options::NoSigintHandler);
  vmap::ros_node::LogThroughRosconsole();
  vmap::ros_node::StopOnSignals();
  if (!vmap::ros_node::WaitForMaster()) return 128 + vmap::ros_node::StopSignal();
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  const int status = vmap::ros_node::RunSimulatorNode(node, private_node);
  ros::shutdown();
  return status;
}
