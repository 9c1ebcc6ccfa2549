#include "vmap_ros/terminate_signal.h"

#include <atomic>
#include <csignal>
#include <string>

#include <ros/ros.h>
#include <ros/xmlrpc_manager.h>

namespace vmap::ros_node {
namespace {

volatile std::sig_atomic_t stop_signal = 0;
std::atomic<bool> master_asked_to_stop{false};

}  // namespace

void StopOnSignals() {
  struct sigaction action = {};
  action.sa_handler = [](int signal) { stop_signal = signal; };
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int StopSignal() { return stop_signal; }

void StopOnShutdownRequests(std::function<void()> first) {
  ros::XMLRPCManager& server = *ros::XMLRPCManager::instance();
  server.unbind("shutdown");
  server.bind("shutdown", [first = std::move(first)](XmlRpc::XmlRpcValue& params, XmlRpc::XmlRpcValue& result) {
    std::string reason = "no reason given";
    if (params.getType() == XmlRpc::XmlRpcValue::TypeArray && params.size() > 1 &&
        params[1].getType() == XmlRpc::XmlRpcValue::TypeString) {
      reason = static_cast<std::string>(params[1]);
    }
    ROS_WARN("the ROS master asks this node to shut down (%s): it stops", reason.c_str());
    first();
    master_asked_to_stop = true;
    result = ros::xmlrpc::responseInt(1, "", 0);
  });
}

bool StopRequested() { return stop_signal != 0 || master_asked_to_stop || !ros::ok() || ros::isShuttingDown(); }

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
          "again): its services and topics are unknown there, while the connections it has go on; restart the node "
          "when the robot may stop (it does not exit by itself, so respawn=\"true\" does not restart it)",
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
