#pragma once
// vmap's closed-loop simulator (simulation/, `vmap simulate`) as a ROS node: the robot's camera, odometry and
// motors on ROS topics, so that a vmap node drives it through ROS as it would drive a robot.
//
// At start-up it teaches the route (the corridor rendered along it, the map built into ~map as `vmap simulate`
// builds it, the teach run's odometry beside it as the vmap node's teach run writes it: pipelines/localize_odometry.h),
// and publishes ~ready (latched). Then, once a vmap node listens to its camera, it runs repeat trial ~trial of `vmap
// simulate`'s options: for each control step it publishes the rendered frame (camera/image_raw, bgr8, with
// camera/camera_info) and the robot's odometry (odom, before the frame), waits for the vmap node's command
// (cmd_vel) and localization message (localization) for that frame, and drives the robot by it: lock-step, so the
// machine's speed changes nothing. The trial ends as `vmap simulate`'s do (the goal reached, the corridor left, the
// time limit), and its result is written to ~result (JSON) beside the same trial run in process (RunTrial: the same
// world, map, start and noise) for comparison.
//
// Parameters: `vmap simulate`'s flags by name (~route, ~seed, ~rate, ~teach_speed, ~lateral_offset, ...),
// ~trial (the trial's index, default 0), ~map, ~result, ~answer_timeout (seconds to wait for the
// vmap node's answer to a frame, default 60).

#include <string>

#include <ros/node_handle.h>

namespace vmap::ros_node {

// Runs the simulator node until its trial ends; returns the process's exit status (0: the trial ran, whatever its
// end; 2: bad options or no answer from the vmap node, logged).
int RunSimulatorNode(ros::NodeHandle& node, ros::NodeHandle& private_node);

}  // namespace vmap::ros_node
