#pragma once
// vmap_ros/Localization (ros/msg/Localization.msg) from a frame's localization and the controller's step.

#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <std_msgs/Header.h>

#include "vmap/localization/localizer.h"

#include "vmap_ros/Localization.h"

namespace vmap::ros_node {

// What the controller made of the frame, as the message carries it.
struct ControlSummary {
  std::string state = "starting";  // the controller's state, or "paused"
  std::string steering = "none";
  bool localized = false;  // a frame has been localized since the repeat started
  geometry_msgs::Twist command;
};

// The message of `result` (the frame whose camera header is `header`) on `route`.
vmap_ros::Localization LocalizationMessage(const std_msgs::Header& header, const LocalizationResult& result,
                                           const std::vector<int>& route, const ControlSummary& control);

// The message's status constant of `status`.
uint8_t StatusConstant(LocalizationStatus status);

}  // namespace vmap::ros_node
