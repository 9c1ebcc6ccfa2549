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

}  // namespace vmap::ros_node
