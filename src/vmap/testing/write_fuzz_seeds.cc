// Writes the seeds of the fuzz targets (fuzz/): small valid recordings of every container and compression,
// and a small JSON document, one folder per target. ctest runs it first (fixture fuzz_seeds).
//
//   write_fuzz_seeds DIR   ->  DIR/ros1_bag/, DIR/mcap/, DIR/rosbag2/, DIR/json/

#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "vmap/testing/hostile_recordings.h"
#include "vmap/testing/recording_writer.h"

namespace {
namespace fs = std::filesystem;
using vmap::MessageEncoding;
using vmap::testing::TestMessage;

// A camera_info, two small raw frames, a compressed one and an IMU message: every kind of record the readers
// and decoders meet, in few bytes (fuzzers mutate small inputs best).
std::vector<TestMessage> Messages(MessageEncoding encoding) {
  std::vector<TestMessage> messages;
  messages.push_back({"/cam/camera_info", "sensor_msgs/CameraInfo", 1'000'000'000,
                      vmap::testing::SerializeCameraInfo(encoding, 1.0, "cam", {8, 6}, "plumb_bob",
                                                         {-0.1, 0.01, 0, 0, 0}, {8, 0, 3.5, 0, 8, 2.5, 0, 0, 1})});
  for (int i = 0; i < 2; ++i) {
    cv::Mat frame(6, 8, CV_8UC3, cv::Scalar(10 * i, 20, 30));
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", 1'100'000'000 + i * 100'000'000LL,
                        vmap::testing::SerializeImage(encoding, 1.1 + 0.1 * i, "cam", frame, i ? "mono8" : "bgr8")});
  }
  std::vector<uint8_t> png;
  cv::imencode(".png", cv::Mat(4, 4, CV_8UC1, cv::Scalar(7)), png);
  messages.push_back({"/cam/image_raw/compressed", "sensor_msgs/CompressedImage", 1'300'000'000,
                      vmap::testing::SerializeCompressedImage(encoding, 1.3, "png", png)});
  messages.push_back({"/imu", "sensor_msgs/Imu", 1'350'000'000, std::vector<uint8_t>(16, 7)});
  return messages;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: write_fuzz_seeds DIR\n";
    return 2;
  }
  const fs::path dir = argv[1];
  for (const char* target : {"ros1_bag", "mcap", "rosbag2", "json"}) fs::create_directories(dir / target);
  for (const char* compression : {"none", "bz2", "lz4"}) {
    vmap::testing::Ros1Chunk chunk;
    chunk.messages = Messages(MessageEncoding::kRos1);
    chunk.compression = compression;
    vmap::testing::WriteRos1BagChunks((dir / "ros1_bag" / (std::string(compression) + ".bag")).string(), {chunk});
    // With an index, as rosbag writes it (when python3-rosbag is there).
    std::string why;
    vmap::testing::WriteRos1Bag((dir / "ros1_bag" / (std::string(compression) + "_indexed.bag")).string(),
                                Messages(MessageEncoding::kRos1), compression, &why);
  }
  for (const char* compression : {"", "none", "zstd", "lz4"}) {
    const std::string name = std::string(*compression ? compression : "unchunked");
    vmap::testing::WriteMcap((dir / "mcap" / (name + ".mcap")).string(), Messages(MessageEncoding::kCdr), compression);
    vmap::testing::WriteMcap((dir / "mcap" / (name + "_no_summary.mcap")).string(), Messages(MessageEncoding::kCdr),
                             compression, 2, /*summary=*/false);
  }
  for (const char* compression : {"", "message"}) {
    const fs::path folder = dir / "rosbag2" / (std::string("bag_") + (*compression ? compression : "plain"));
    vmap::testing::WriteRosbag2(folder.string(), Messages(MessageEncoding::kCdr), compression);
    fs::rename(folder / (folder.filename().string() + "_0.db3"),
               dir / "rosbag2" / (folder.filename().string() + ".db3"));
    fs::remove_all(folder);
  }
  std::ofstream(dir / "json" / "map.json")
      << R"({"format": "vmap-map", "schema_version": 2, "input": {"path": "a.mp4", "frame_size": [640, 480]},)"
      << R"( "key_images": [{"frame_index": 0, "image": "keys/000000.png"}], "links": [], "quality": 0.5,)"
      << R"( "evaluations": {"key_frame": [0, 0], "similarity": [1.0, 0.5e-3]}, "experiences": [{"id": 1}]})";
  return 0;
}
