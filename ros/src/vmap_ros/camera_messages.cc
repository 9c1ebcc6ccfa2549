#include "vmap_ros/camera_messages.h"

#include "vmap/core/error.h"
#include "vmap/sources/recording_reader.h"
#include "vmap/sources/ros_image_messages.h"

namespace vmap::ros_node {

CameraImage DecodeCameraImage(const topic_tools::ShapeShifter& message, const std::string& topic) {
  const std::string type = message.getDataType();
  const std::string what = "a " + type + " message on " + topic;
  if (!IsImageType(type)) {
    throw InputError(topic + " carries " + type +
                     " messages; vmap reads sensor_msgs/Image and sensor_msgs/CompressedImage: remap `image` to "
                     "the camera's image topic");
  }
  std::vector<uint8_t> bytes(message.size());
  ros::serialization::OStream out(bytes.data(), static_cast<uint32_t>(bytes.size()));
  message.write(out);

  CameraImage image;
  try {
    ros::serialization::IStream header(bytes.data(), static_cast<uint32_t>(bytes.size()));
    ros::serialization::deserialize(header, image.header);
  } catch (const ros::Exception&) {
    throw InputError(what + " is malformed: it is too short for its header");
  }
  DecodedImage decoded = DecodeImageMessage(bytes.data(), bytes.size(), type, MessageEncoding::kRos1, what);
  image.stamp = image.header.stamp.isZero() ? -1.0 : image.header.stamp.toSec();
  image.gray = std::move(decoded.gray);
  image.color = std::move(decoded.color);
  return image;
}

std::optional<Camera> CameraFromInfo(const sensor_msgs::CameraInfo& info, const std::string& topic) {
  const std::vector<uint8_t> bytes = SerializeMessage(info);
  const std::string what = "the CameraInfo on " + topic;
  std::optional<Camera> camera = DecodeCameraInfo(bytes.data(), bytes.size(), MessageEncoding::kRos1, what);
  if (!camera) return std::nullopt;
  camera->origin = topic;
  camera->Check();  // "the camera from /cam/camera_info has a parameter that is not a finite number"
  return camera;
}

}  // namespace vmap::ros_node
