#pragma once
// vmap's log (spdlog) into ROS's (rosconsole, and so /rosout): a node's warnings reach the robot's operators
// where the rest of ROS's do.

namespace vmap::ros_node {

// Makes spdlog's default logger write through rosconsole at the same levels. Call once, before any thread logs.
void LogThroughRosconsole();

}  // namespace vmap::ros_node
