#pragma once
// SIGTERM ends a node as SIGINT does. roscpp handles only SIGINT, but roslaunch escalates to SIGTERM after 15 s
// and systemd and `docker stop` send it first: killed by it, a teach run would lose the map it was building.

namespace vmap::ros_node {

// After ros::init: SIGTERM requests the same shutdown as SIGINT (ros::waitForShutdown returns, the node's
// destructor finishes its run).
void ShutDownOnTerminateSignal();

}  // namespace vmap::ros_node
