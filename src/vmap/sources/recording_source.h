#pragma once
// A robot's recording (ROS 1 bag, rosbag2 folder, MCAP file) as a frame source: the frames of one image
// topic, ordered by their header stamps, with the camera of its CameraInfo topic.
//
// Which topics: --topic names the image topic (sensor_msgs/Image or CompressedImage); without it the
// recording's only image topic. The camera comes from --camera-topic, by default the image topic's sibling
// `camera_info` as ROS's image_transport pairs them (/cam/image_raw and /cam/image_raw/compressed both go with
// /cam/camera_info).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/sources/recording_reader.h"

namespace vmap {

// The image topic to read: `requested` when it is an image topic of the recording, else the only image topic.
// Throws InputError that lists the image topics (type, message count) when there is no single answer.
std::string ChooseImageTopic(const std::vector<RecordingTopic>& topics, const std::string& requested,
                             const std::string& path);

// The CameraInfo topic image_transport pairs with an image topic.
std::string CameraInfoTopicFor(const std::string& image_topic);

// What `vmap info RECORDING` prints: each topic with its type, message count, rate and, for image topics,
// the size of its first image.
struct RecordingTopicSummary {
  RecordingTopic topic;
  double rate_hz = 0.0;  // messages per second of log time; 0 with fewer than two messages
  cv::Size image_size;   // image topics only
};
std::vector<RecordingTopicSummary> DescribeRecording(const std::string& path);
std::string FormatRecordingTopics(const std::string& path, const std::vector<RecordingTopicSummary>& topics);

}  // namespace vmap
