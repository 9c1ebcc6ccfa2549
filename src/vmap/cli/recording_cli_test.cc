// The vmap binary on robot recordings: a bag holding a video's decoded frames gives the video's map, for each
// container; `vmap info` lists a recording's topics; several image topics and no --topic is refused.

#include <algorithm>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/map/map_io.h"
#include "vmap/sources/dataset_camera.h"
#include "vmap/sources/frame_source.h"
#include "vmap/testing/recording_writer.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using testing::Quote;
using testing::RunVmap;
using testing::TestMessage;

constexpr int kVideoFrames = 100;

// The first frames of lab_floor.mp4, as a camera driver would publish them: raw bgr8 on /cam/image_raw, JPEG on
// /cam/image_raw/compressed, the video's intrinsics on /cam/camera_info; header stamps are the video's times.
std::vector<TestMessage> VideoMessages(const std::string& video, MessageEncoding encoding) {
  FrameSourceOptions options;
  options.last = kVideoFrames - 1;
  std::unique_ptr<FrameSource> source = OpenFrameSource(video, options);
  std::vector<TestMessage> messages;
  const int64_t start_ns = 1'700'000'000'000'000'000;
  while (std::optional<Frame> frame = source->Next()) {
    const double stamp = 1.7e9 + frame->timestamp;
    const int64_t log_ns = start_ns + static_cast<int64_t>(frame->timestamp * 1e9) + 2'000'000;
    if (frame->index == 0) {
      const Camera camera = *source->info().camera;
      messages.push_back({"/cam/camera_info", "sensor_msgs/CameraInfo", log_ns,
                          testing::SerializeCameraInfo(encoding, stamp, "cam", frame->color.size(), "plumb_bob",
                                                       camera.distortion(), camera.K())});
    }
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", log_ns,
                        testing::SerializeImage(encoding, stamp, "cam", frame->color, "bgr8")});
    std::vector<uint8_t> jpeg;
    cv::imencode(".jpg", frame->color, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
    messages.push_back({"/cam/image_raw/compressed", "sensor_msgs/CompressedImage", log_ns,
                        testing::SerializeCompressedImage(encoding, stamp, "jpeg", jpeg)});
  }
  return messages;
}

std::vector<int> KeySourceIndices(const VisualMap& map) {
  std::vector<int> indices;
  for (const KeyImage& key : map.key_images) indices.push_back(key.source_index);
  return indices;
}

TEST(RecordingCli, ARecordingOfAVideosFramesGivesTheVideosMap) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp("recording_map");
  const std::string video = testing::SharedDir() + "/data/lab_floor/lab_floor.mp4";
  std::string out;
  const fs::path video_map = tmp.path() / "video_map";
  ASSERT_EQ(
      RunVmap("build " + Quote(video) + " -q --last " + std::to_string(kVideoFrames - 1) + " -o " + Quote(video_map),
              &out),
      0)
      << out;
  const VisualMap expected = ReadMap(video_map);
  ASSERT_GE(expected.key_images.size(), 2u);

  std::vector<std::string> recordings;
  const std::string mcap = (tmp.path() / "run.mcap").string();
  testing::WriteMcap(mcap, VideoMessages(video, MessageEncoding::kCdr), "zstd", 8);
  recordings.push_back(mcap);
  const std::string rosbag2 = (tmp.path() / "run_ros2").string();
  testing::WriteRosbag2(rosbag2, VideoMessages(video, MessageEncoding::kCdr));
  recordings.push_back(rosbag2);
  const std::string bag = (tmp.path() / "run.bag").string();
  std::string why;
  if (testing::WriteRos1Bag(bag, VideoMessages(video, MessageEncoding::kRos1), "lz4", &why)) {
    recordings.push_back(bag);
  } else {
    ADD_FAILURE() << why;
  }
  for (const std::string& recording : recordings) {
    SCOPED_TRACE(recording);
    const fs::path raw_map = tmp.path() / (fs::path(recording).filename().string() + "_raw");
    ASSERT_EQ(RunVmap("build " + Quote(recording) + " -q --topic /cam/image_raw -o " + Quote(raw_map), &out), 0) << out;
    const VisualMap raw = ReadMap(raw_map);
    EXPECT_EQ(raw.num_frames, kVideoFrames);
    EXPECT_EQ(KeySourceIndices(raw), KeySourceIndices(expected));
    ASSERT_EQ(raw.key_images.size(), expected.key_images.size());
    for (size_t k = 0; k < raw.key_images.size(); ++k) {
      EXPECT_NEAR(raw.key_images[k].timestamp, 1.7e9 + expected.key_images[k].timestamp, 1e-6);  // header stamps
      const cv::Mat a = cv::imread((raw_map / raw.key_images[k].image_file).string());
      const cv::Mat b = cv::imread((video_map / expected.key_images[k].image_file).string());
      EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << "key image " << k;
    }
    EXPECT_NE(raw.input.camera, std::nullopt);

    // JPEG frames differ a little from the video's: a sane map, not the same one.
    const fs::path jpeg_map = tmp.path() / (fs::path(recording).filename().string() + "_jpeg");
    ASSERT_EQ(
        RunVmap("build " + Quote(recording) + " -q --topic /cam/image_raw/compressed -o " + Quote(jpeg_map), &out), 0)
        << out;
    const VisualMap jpeg = ReadMap(jpeg_map);
    EXPECT_EQ(jpeg.num_frames, kVideoFrames);
    EXPECT_GE(jpeg.key_images.size(), expected.key_images.size() / 2 + 1);
    EXPECT_LE(jpeg.key_images.size(), expected.key_images.size() * 2);
    if (recording != mcap) continue;
    // Repeat against teach: the JPEG frames localized against the raw frames' map (every 5th, to be quick).
    const fs::path csv = tmp.path() / "repeat.csv";
    ASSERT_EQ(RunVmap("localize " + Quote(raw_map) + " " + Quote(recording) +
                          " -q --topic /cam/image_raw/compressed --stride 5 --csv " + Quote(csv),
                      &out),
              0)
        << out;
    std::ifstream lines(csv);
    EXPECT_EQ(std::count(std::istreambuf_iterator<char>(lines), std::istreambuf_iterator<char>(), '\n'),
              1 + kVideoFrames / 5);  // a header and one line per frame
  }
}

TEST(RecordingCli, InfoListsTopicsAndBuildRefusesToGuess) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir dir("recording_cli");
  const std::string path = (dir.path() / "run.mcap").string();
  std::vector<TestMessage> messages =
      VideoMessages(testing::SharedDir() + "/data/lab_floor/lab_floor.mp4", MessageEncoding::kCdr);
  messages.resize(3 * 20);  // 20 frames
  testing::WriteMcap(path, messages, "lz4");
  std::string output;
  EXPECT_EQ(testing::RunVmap("info " + testing::Quote(path), &output), 0) << output;
  EXPECT_NE(output.find("/cam/image_raw/compressed"), std::string::npos) << output;
  EXPECT_NE(output.find("640x480"), std::string::npos) << output;
  const fs::path map = dir.path() / "map";
  EXPECT_EQ(testing::RunVmap("build " + testing::Quote(path) + " -o " + testing::Quote(map), &output), 2) << output;
  EXPECT_NE(output.find("choose one with --topic"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(map));
  EXPECT_EQ(testing::RunVmap("build " + testing::Quote(path) + " --topic /cam/image_raw -q -o " + testing::Quote(map),
                             &output),
            0)
      << output;
  EXPECT_TRUE(fs::exists(map / "map.json"));
}

}  // namespace
}  // namespace vmap
