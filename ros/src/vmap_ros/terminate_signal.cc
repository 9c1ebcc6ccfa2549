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
  // The master is asked every 2 s: a node whose master went away goes on over the connections it has, but one that
  // comes back does not know the node (ROS 1 nodes do not register again), which then stays deaf to new
  // subscribers and service calls: said, for the operator to restart it.
  bool reachable = true;
  for (int tick = 1; !StopRequested(); ++tick) {
    ros::WallDuration(0.05).sleep();
    if (tick % 40 != 0) continue;
    const bool now = ros::master::check();
    if (reachable && !now) {
      ROS_WARN("the ROS master at %s is gone: the topics already connected go on, nothing new connects",
               ros::master::getURI().c_str());
    } else if (!reachable && now) {
      ROS_ERROR(
          "a ROS master is back at %s, but this node is not registered with it (ROS 1 nodes do not register "
          "again): its services and topics are unknown there; restart the node (roslaunch: respawn=\"true\")",
          ros::master::getURI().c_str());
    }
    reachable = now;
  }
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
