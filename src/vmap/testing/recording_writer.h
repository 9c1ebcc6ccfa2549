#pragma once
// Small robot recordings for tests: ROS messages serialized for ROS 1 or ROS 2 (CDR), written as an MCAP file
// (chunks uncompressed, zstd or lz4), a rosbag2 sqlite3 folder, or a ROS 1 bag (through Debian's
// python3-rosbag, an implementation independent of vmap's reader; chunks none, bz2 or lz4).

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/sources/recording_reader.h"

namespace vmap::testing {

struct TestMessage {
  std::string topic;
  std::string type;  // ROS 1's spelling ("sensor_msgs/Image"); the ROS 2 writers insert "/msg/"
  int64_t log_time_ns = 0;
  std::vector<uint8_t> data;
};

// sensor_msgs/Image with `encoding` (mono8, mono16, rgb8, bgr8, rgba8, bgra8, bayer_*8): `pixels` is stored
// as is, row by row (its type must fit the encoding), with `padding` extra bytes per row (step > width).
std::vector<uint8_t> SerializeImage(MessageEncoding encoding, double stamp, const std::string& frame_id,
                                    const cv::Mat& pixels, const std::string& image_encoding, int padding = 0);
std::vector<uint8_t> SerializeCompressedImage(MessageEncoding encoding, double stamp, const std::string& format,
                                              const std::vector<uint8_t>& bytes);
std::vector<uint8_t> SerializeCameraInfo(MessageEncoding encoding, double stamp, const std::string& frame_id,
                                         cv::Size size, const std::string& model, const std::vector<double>& d,
                                         const cv::Matx33d& k);

// nav_msgs/Odometry at (x, y) turned `yaw` about z (covariances and twist zero).
std::vector<uint8_t> SerializeOdometry(MessageEncoding encoding, double stamp, double x, double y, double yaw);

// compression: "" (unchunked), "none" (chunks, uncompressed), "zstd" or "lz4"; `per_chunk` messages a chunk.
// `summary`: the summary section (schemas, channels, chunk indexes, statistics) as recorders write it; a
// recording cut short has none.
void WriteMcap(const std::string& path, const std::vector<TestMessage>& messages, const std::string& compression,
               int per_chunk = 4, bool summary = true);
// A rosbag2 folder: metadata.yaml and FOLDER_0.db3. compression, as `ros2 bag record --compression-format zstd
// --compression-mode MODE` writes it: "" (none), "message" (each message a zstd frame) or "file"
// (FOLDER_0.db3.zstd).
void WriteRosbag2(const std::string& folder, const std::vector<TestMessage>& messages,
                  const std::string& compression = "");
// compression: "none", "bz2" or "lz4". Returns false (and the reason in *why) when python3-rosbag is missing.
bool WriteRos1Bag(const std::string& path, const std::vector<TestMessage>& messages, const std::string& compression,
                  std::string* why);

}  // namespace vmap::testing
