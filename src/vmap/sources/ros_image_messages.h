#pragma once
// The three ROS message types vmap reads from a recording, decoded from either serialization:
// sensor_msgs/Image (mono8, mono16, rgb8, bgr8, rgba8, bgra8, bayer_*8), sensor_msgs/CompressedImage (any
// format OpenCV decodes: jpeg, png) and sensor_msgs/CameraInfo (plumb_bob, rational_polynomial, equidistant).

#include <cstdint>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "vmap/geometry/camera.h"
#include "vmap/sources/recording_reader.h"

namespace vmap {

inline constexpr const char* kImageType = "sensor_msgs/Image";
inline constexpr const char* kCompressedImageType = "sensor_msgs/CompressedImage";
inline constexpr const char* kCameraInfoType = "sensor_msgs/CameraInfo";

bool IsImageType(const std::string& type);  // Image or CompressedImage, ROS 1 or ROS 2 spelling

struct DecodedImage {
  double stamp = -1.0;  // header.stamp in seconds
  cv::Mat color;        // BGR, empty for a grey image
  cv::Mat gray;         // always set
};

// Decodes an Image or CompressedImage message (`type` as the recording names it). Throws InputError naming
// `what` (e.g. "message 12 of /cam/image_raw in 'run.bag'") when the message is malformed or its encoding
// is not one vmap reads.
DecodedImage DecodeImageMessage(const uint8_t* data, size_t size, const std::string& type, MessageEncoding encoding,
                                const std::string& what);

// The size of the image a message holds, from its fields (raw) or its image header (compressed).
cv::Size ImageMessageSize(const uint8_t* data, size_t size, const std::string& type, MessageEncoding encoding,
                          const std::string& what);

// The camera of a CameraInfo message: K and D at its width x height. nullopt for an uncalibrated camera (K all
// zero, as camera drivers publish before calibration). plumb_bob and rational_polynomial give OPENCV /
// FULL_OPENCV cameras, equidistant an OPENCV_FISHEYE one. Throws InputError for another distortion model or a
// wrong coefficient count, naming the fix (--camera).
std::optional<Camera> DecodeCameraInfo(const uint8_t* data, size_t size, MessageEncoding encoding,
                                       const std::string& what);

}  // namespace vmap
