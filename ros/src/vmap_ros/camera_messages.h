#pragma once
// The camera's messages as vmap frames. An image topic is read whatever its type, sensor_msgs/Image or
// CompressedImage (a topic_tools::ShapeShifter subscription: one remapping serves both), and decoded from its
// serialized bytes by the decoder `vmap build` and `vmap localize` use on a recorded bag
// (sources/ros_image_messages.h): a topic and its recording give the same frames, pixel for pixel, and the same
// checks refuse the same malformed messages. Debian packages no compressed image_transport plugin, which is why
// compressed images are not read through image_transport.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <std_msgs/Header.h>
#include <topic_tools/shape_shifter.h>

#include "vmap/geometry/camera.h"

namespace vmap::ros_node {

// One decoded camera image.
struct CameraImage {
  std_msgs::Header header;  // as the camera sent it (stamp, frame_id)
  double stamp = -1.0;      // header.stamp in seconds; -1 when the camera left it zero
  cv::Mat gray;             // 8-bit grey: what the matchers see
  cv::Mat color;            // 8-bit BGR for a colour image, else empty
};

// Decodes a message of image topic `topic`. Throws InputError naming the topic and what is wrong: a type other
// than Image or CompressedImage, a malformed message (data shorter than height x step, a step shorter than a
// row), an encoding vmap does not read, a compressed image OpenCV cannot decode.
CameraImage DecodeCameraImage(const topic_tools::ShapeShifter& message, const std::string& topic);

// The camera of a CameraInfo message of `topic`, as `vmap build` reads it from a bag; nullopt for an uncalibrated
// camera (K all zero). Throws InputError naming the topic for a distortion model vmap does not know or values
// that cannot be a camera's (NaN, infinite or non-positive focal lengths).
std::optional<Camera> CameraFromInfo(const sensor_msgs::CameraInfo& info, const std::string& topic);

// The serialized bytes of a ROS message.
template <typename Message>
std::vector<uint8_t> SerializeMessage(const Message& message);

}  // namespace vmap::ros_node

#include <ros/serialization.h>

namespace vmap::ros_node {

template <typename Message>
std::vector<uint8_t> SerializeMessage(const Message& message) {
  std::vector<uint8_t> bytes(ros::serialization::serializationLength(message));
  ros::serialization::OStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
  ros::serialization::serialize(stream, message);
  return bytes;
}

}  // namespace vmap::ros_node
