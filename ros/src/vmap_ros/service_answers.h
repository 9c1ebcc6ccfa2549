#pragma once
// The node's answers to a service call, logged as they are given. A request that cannot be done is answered, not
// failed: the call succeeds and its response says why (ROS reports a failed call without the reason).

#include <string>

#include <ros/console.h>

namespace vmap::ros_node {

template <typename Response>
bool Fail(Response& response, const std::string& message) {
  ROS_ERROR("%s", message.c_str());
  response.success = false;
  response.message = message;
  return true;
}

template <typename Response>
bool Succeed(Response& response, const std::string& message) {
  ROS_INFO("%s", message.c_str());
  response.success = true;
  response.message = message;
  return true;
}

}  // namespace vmap::ros_node
