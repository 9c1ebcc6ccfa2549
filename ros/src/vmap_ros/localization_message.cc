#include "vmap_ros/localization_message.h"

#include <Eigen/Geometry>

namespace vmap::ros_node {

uint8_t StatusConstant(LocalizationStatus status) {
  switch (status) {
    case LocalizationStatus::kTracking:
      return vmap_ros::Localization::TRACKING;
    case LocalizationStatus::kRelocalized:
      return vmap_ros::Localization::RELOCALIZED;
    case LocalizationStatus::kUncertain:
      return vmap_ros::Localization::UNCERTAIN;
    case LocalizationStatus::kLost:
      break;
  }
  return vmap_ros::Localization::LOST;
}

vmap_ros::Localization LocalizationMessage(const std_msgs::Header& header, const LocalizationResult& result,
                                           const std::vector<int>& route, const ControlSummary& control) {
  vmap_ros::Localization message;
  message.header = header;
  message.status = StatusConstant(result.status);
  message.status_name = LocalizationStatusName(result.status);
  message.key = result.key;
  message.next_key = result.next_key;
  message.goal = route.empty() ? -1 : route.back();
  message.route_position = result.route_position;
  message.route_length = static_cast<int>(route.size());
  message.progress = result.progress;
  message.confidence = result.confidence;
  message.key_rank = result.key_rank;
  message.motion_steps = result.motion_steps;
  message.heading_px = result.heading_px;
  message.heading_deg = result.heading_deg;
  message.heading_key_px = result.heading_key_px;
  message.heading_key_deg = result.heading_key_deg;

  // The target's pose: next_key's, or key's at the route's end (LocalizationResult).
  const KeyComparison& target = result.next_key >= 0 ? result.to_next : result.to_key;
  message.pose.orientation.w = 1.0;
  if (target.pose.valid) {
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = target.pose.R(r, c);
    }
    const Eigen::Quaterniond q(R);
    message.pose.orientation.x = q.x();
    message.pose.orientation.y = q.y();
    message.pose.orientation.z = q.z();
    message.pose.orientation.w = q.w();
    message.pose.position.x = target.pose.t[0];
    message.pose.position.y = target.pose.t[1];
    message.pose.position.z = target.pose.t[2];
    message.pose_valid = true;
  }
  message.translation_known = result.translation_known;
  message.guidance = LocalizationGuidance(result);
  message.verified_key = result.to_key.num_verified;
  message.verified_next = result.to_next.num_verified;
  message.similarity_key = result.to_key.similarity;
  message.similarity_next = result.to_next.similarity;

  message.controller_state = control.state;
  message.steering = control.steering;
  message.localized = control.localized;
  message.command = control.command;
  return message;
}

}  // namespace vmap::ros_node
