#include "vmap_ros/terminate_signal.h"

#include <csignal>

#include <ros/ros.h>

namespace vmap::ros_node {
namespace {

volatile std::sig_atomic_t stop_signal = 0;

}  // namespace

void StopOnSignals() {
  struct sigaction action = {};
  action.sa_handler = [](int signal) { stop_signal = signal; };
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int StopSignal() { return stop_signal; }

bool StopRequested() { return stop_signal != 0 || !ros::ok() || ros::isShuttingDown(); }

void WaitForStop() {
  while (!StopRequested()) ros::WallDuration(0.05).sleep();
}

bool WaitForMaster() {
  for (int tries = 0; stop_signal == 0 && !ros::master::check(); ++tries) {
    if (tries % 200 == 0)
      ROS_WARN("waiting for the ROS master at %s (is roscore running?)", ros::master::getURI().c_str());
    ros::WallDuration(0.05).sleep();
  }
  return stop_signal == 0;
}

}  // namespace vmap::ros_node
