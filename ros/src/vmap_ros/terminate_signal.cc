#include "vmap_ros/terminate_signal.h"

#include <csignal>

#include <ros/ros.h>

namespace vmap::ros_node {

void ShutDownOnTerminateSignal() {
  struct sigaction action = {};
  // ros::requestShutdown only sets a flag that roscpp's poll thread acts on: what its own SIGINT handler calls.
  action.sa_handler = [](int) { ros::requestShutdown(); };
  sigemptyset(&action.sa_mask);
  sigaction(SIGTERM, &action, nullptr);
}

}  // namespace vmap::ros_node
