#pragma once
// How a vmap node ends: SIGINT (Ctrl-C, roslaunch) and SIGTERM (roslaunch 15 s later, systemd, `docker stop`) ask it
// to stop, and the node stops its robot and finishes a teach run's map while ROS is still up. roscpp's own SIGINT
// handler shuts ROS down at once, after which a node can neither publish a last zero command nor log; and roscpp
// leaves SIGTERM to kill the process, losing the map. Call after ros::init(..., ros::init_options::NoSigintHandler).

#include <functional>

namespace vmap::ros_node {

// SIGINT and SIGTERM set the stop request (async-signal-safe: one flag).
void StopOnSignals();
// The signal that asked to stop (SIGINT, SIGTERM), or 0.
int StopSignal();
// The ROS master's request to shut down (another node registered under this node's name, `rosnode kill`) runs
// `first` at once (the robot stopped) and asks to stop as a signal does. roscpp's own answer shut ROS down at once,
// after which the node could not stop its robot, which kept its last command. Call after the first NodeHandle.
void StopOnShutdownRequests(std::function<void()> first);
// A signal or the master asked to stop, or ROS is shutting down.
bool StopRequested();
// Sleeps until StopRequested().
void WaitForStop();
// Waits until the ROS master answers, saying where it looks every 10 s; false when a signal asks to stop first.
// Call before the first NodeHandle: roscpp would otherwise retry the master for ever, and the handlers above only
// set a flag, so a node started before roscore was deaf to SIGINT and SIGTERM.
bool WaitForMaster();

}  // namespace vmap::ros_node
