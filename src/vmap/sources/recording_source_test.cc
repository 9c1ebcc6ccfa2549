#include "vmap/sources/recording_source.h"

#include <sqlite3.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/sources/dataset_camera.h"
#include "vmap/sources/frame_source.h"
#include "vmap/testing/recording_writer.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using testing::TestMessage;

constexpr int kFrames = 12;
const cv::Size kSize(96, 64);

cv::Mat FrameImage(int i) {
  cv::Mat image(kSize, CV_8UC3);
  cv::RNG rng(i + 1);  // the same image each time it is asked for
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  cv::putText(image, std::to_string(i), {10, 50}, cv::FONT_HERSHEY_SIMPLEX, 1.5, cv::Scalar(255, 0, 255 - 20 * i), 3);
  return image;
}

double Stamp(int i) { return 100.0 + 0.1 * i; }

// One recording's messages: /cam/camera_info once, then the frames on /cam/image_raw (bgr8) and
// /cam/image_raw/compressed (png), with /imu between them; stored by receive time, frames in pairs swapped
// (1, 0, 3, 2, ...) so that only their header stamps give their order.
std::vector<TestMessage> Messages(MessageEncoding encoding) {
  std::vector<TestMessage> messages;
  int64_t time = 1'000'000'000;
  messages.push_back({"/cam/camera_info", "sensor_msgs/CameraInfo", time,
                      testing::SerializeCameraInfo(encoding, Stamp(0), "cam", kSize, "plumb_bob", {-0.1, 0.01, 0, 0, 0},
                                                   {80, 0, 47.5, 0, 80, 31.5, 0, 0, 1})});
  for (int stored = 0; stored < kFrames; ++stored) {
    const int i = stored ^ 1;
    time += 100'000'000;
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", time,
                        testing::SerializeImage(encoding, Stamp(i), "cam", FrameImage(i), "bgr8")});
    std::vector<uint8_t> png;
    cv::imencode(".png", FrameImage(i), png);
    messages.push_back({"/cam/image_raw/compressed", "sensor_msgs/CompressedImage", time,
                        testing::SerializeCompressedImage(encoding, Stamp(i), "png", png)});
    messages.push_back({"/imu", "sensor_msgs/Imu", time, std::vector<uint8_t>(40, 7)});
  }
  return messages;
}

struct Container {
  std::string name;         // for traces
  std::string compression;  // as the writer takes it
};
const Container kContainers[] = {{"bag", "none"},        {"bag", "bz2"},      {"bag", "lz4"}, {"rosbag2", ""},
                                 {"rosbag2", "message"}, {"rosbag2", "file"}, {"mcap", ""},   {"mcap", "none"},
                                 {"mcap", "zstd"},       {"mcap", "lz4"}};

// Writes the recording; "" with the reason in *why when it cannot (ROS 1 bags need python3-rosbag).
std::string Write(const fs::path& dir, const Container& container, std::string* why) {
  const fs::path path =
      dir / (container.name + "_" + (container.compression.empty() ? "plain" : container.compression));
  if (container.name == "bag") {
    const std::string bag = path.string() + ".bag";
    return testing::WriteRos1Bag(bag, Messages(MessageEncoding::kRos1), container.compression, why) ? bag : "";
  }
  if (container.name == "rosbag2") {
    testing::WriteRosbag2(path.string(), Messages(MessageEncoding::kCdr), container.compression);
    return path.string();
  }
  testing::WriteMcap(path.string() + ".mcap", Messages(MessageEncoding::kCdr), container.compression);
  return path.string() + ".mcap";
}

std::vector<Frame> ReadAll(const std::string& path, const FrameSourceOptions& options, SequenceInfo* info = nullptr) {
  std::unique_ptr<FrameSource> source = OpenFrameSource(path, options);
  std::vector<Frame> frames;
  while (auto frame = source->Next()) frames.push_back(std::move(*frame));
  if (info) *info = source->info();
  return frames;
}

std::string ErrorOf(const std::function<void()>& work) {
  try {
    work();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(RecordingSource, EveryContainerGivesTheFramesInStampOrderWithTheirCamera) {
  testing::ScopedTempDir dir("recording");
  for (const Container& container : kContainers) {
    SCOPED_TRACE(container.name + " " + container.compression);
    std::string why;
    const std::string path = Write(dir.path(), container, &why);
    if (path.empty()) {
      ADD_FAILURE() << why;
      continue;
    }
    EXPECT_EQ(DetectSourceFormat(path), SourceFormat::kRecording);
    for (const char* topic : {"/cam/image_raw", "/cam/image_raw/compressed"}) {
      FrameSourceOptions options;
      options.topic = topic;
      SequenceInfo info;
      const std::vector<Frame> frames = ReadAll(path, options, &info);
      ASSERT_EQ(frames.size(), static_cast<size_t>(kFrames));
      EXPECT_EQ(info.expected_frames, kFrames);
      for (int i = 0; i < kFrames; ++i) {
        EXPECT_NEAR(frames[i].timestamp, Stamp(i), 1e-6);
        EXPECT_EQ(cv::norm(frames[i].color, FrameImage(i), cv::NORM_INF), 0.0) << "frame " << i;
      }
      ASSERT_TRUE(info.camera);  // from /cam/camera_info, the sibling of both image topics
      EXPECT_EQ(info.camera->fx, 80);
      EXPECT_EQ(info.camera->k1, -0.1);
    }
    FrameSourceOptions options;
    options.topic = "/cam/image_raw";
    options.first = 2;
    options.last = 9;
    options.stride = 3;
    options.camera = "none";
    SequenceInfo info;
    const std::vector<Frame> frames = ReadAll(path, options, &info);
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_EQ(info.expected_frames, 3);
    EXPECT_FALSE(info.camera);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(frames[k].source_index, 2 + 3 * k);
      EXPECT_NEAR(frames[k].timestamp, Stamp(2 + 3 * k), 1e-6);
    }
  }
}

TEST(RecordingSource, TopicsAreListedAndChosen) {
  testing::ScopedTempDir dir("recording_topics");
  std::string why;
  const std::string path = Write(dir.path(), {"mcap", "zstd"}, &why);
  // Counted from the MCAP summary, from its records (a file without a summary), and from a ROS 1 bag's index.
  const std::string unsummarized = (dir.path() / "no_summary.mcap").string();
  testing::WriteMcap(unsummarized, Messages(MessageEncoding::kCdr), "lz4", 4, /*summary=*/false);
  std::vector<std::string> paths = {path, unsummarized};
  const std::string bag = Write(dir.path(), {"bag", "lz4"}, &why);
  if (!bag.empty()) paths.push_back(bag);
  for (const std::string& recording : paths) {
    SCOPED_TRACE(recording);
    const std::vector<RecordingTopicSummary> topics = DescribeRecording(recording);
    ASSERT_EQ(topics.size(), 4u);
    for (const RecordingTopicSummary& summary : topics) {
      if (summary.topic.name == "/cam/camera_info") {
        EXPECT_EQ(summary.topic.message_count, 1);
        continue;
      }
      EXPECT_EQ(summary.topic.message_count, kFrames) << summary.topic.name;
      // Exactly 10 Hz from the records; indexes give the times of chunks, which hold a few messages.
      EXPECT_NEAR(summary.rate_hz, 10.0, recording == unsummarized ? 1e-9 : 1.5) << summary.topic.name;
      if (summary.topic.name != "/imu") {
        EXPECT_EQ(summary.image_size, kSize) << summary.topic.name;
      }
    }
  }
  // Two image topics: no guess, an error that lists them with their types and counts.
  const std::string several = ErrorOf([&] { ReadAll(path, {}); });
  EXPECT_NE(several.find("--topic"), std::string::npos) << several;
  EXPECT_NE(several.find("/cam/image_raw (sensor_msgs/msg/Image, 12 messages)"), std::string::npos) << several;
  EXPECT_NE(several.find("/cam/image_raw/compressed (sensor_msgs/msg/CompressedImage, 12 messages)"), std::string::npos)
      << several;
  FrameSourceOptions imu;
  imu.topic = "/imu";
  EXPECT_NE(ErrorOf([&] { ReadAll(path, imu); }).find("not an image topic"), std::string::npos);
  FrameSourceOptions camera_topic;
  camera_topic.topic = "/cam/image_raw";
  camera_topic.camera_topic = "/left/camera_info";
  EXPECT_NE(ErrorOf([&] { ReadAll(path, camera_topic); }).find("--camera-topic /left/camera_info"), std::string::npos);
  EXPECT_EQ(CameraInfoTopicFor("/cam/image_raw"), "/cam/camera_info");
  EXPECT_EQ(CameraInfoTopicFor("/cam/image_raw/compressed"), "/cam/camera_info");
  EXPECT_EQ(CameraInfoTopicFor("image"), "camera_info");
}

// A recording cut short, or with bytes overwritten, gives the frames before the damage (with a warning) or an
// InputError naming the file; never a crash, never a read past the end.
// A topic whose publisher changed type during the recording (raw, then compressed): each message is decoded by its
// own channel's type (they were all decoded as the first one's, and half were skipped as truncated).
TEST(RecordingSource, EachMessageIsDecodedByItsOwnChannelsType) {
  testing::ScopedTempDir tmp;
  std::vector<TestMessage> messages;
  for (int i = 0; i < kFrames; ++i) {
    const int64_t time = 1'000'000'000 + i * 100'000'000LL;
    if (i < kFrames / 2) {
      messages.push_back({"/cam/image", "sensor_msgs/Image", time,
                          testing::SerializeImage(MessageEncoding::kCdr, Stamp(i), "cam", FrameImage(i), "bgr8")});
    } else {
      std::vector<uint8_t> png;
      cv::imencode(".png", FrameImage(i), png);
      messages.push_back({"/cam/image", "sensor_msgs/CompressedImage", time,
                          testing::SerializeCompressedImage(MessageEncoding::kCdr, Stamp(i), "png", png)});
    }
  }
  for (const bool summary : {true, false}) {  // the topics from the index, then counted by reading
    const std::string path = (tmp.path() / (summary ? "indexed.mcap" : "cut.mcap")).string();
    testing::WriteMcap(path, messages, "none", 4, summary);
    FrameSourceOptions options;
    options.topic = "/cam/image";
    const std::vector<Frame> frames = ReadAll(path, options);
    ASSERT_EQ(frames.size(), static_cast<size_t>(kFrames)) << path;
    for (int i = 0; i < kFrames; ++i) {
      cv::Mat grey;
      cv::cvtColor(FrameImage(i), grey, cv::COLOR_BGR2GRAY);
      ASSERT_EQ(frames[i].gray.size(), kSize) << path << " frame " << i;
      EXPECT_LE(cv::norm(frames[i].gray, grey, cv::NORM_INF), 1.0) << path << " frame " << i;
      EXPECT_DOUBLE_EQ(frames[i].timestamp, Stamp(i)) << path << " frame " << i;
    }
  }
}

TEST(RecordingSource, DamagedRecordingsGiveTheFramesBeforeTheDamageOrAnError) {
  testing::ScopedTempDir dir("recording_damage");
  for (const Container& container : kContainers) {
    if (container.name == "rosbag2") continue;  // sqlite checks its own pages
    SCOPED_TRACE(container.name + " " + container.compression);
    std::string why;
    const std::string path = Write(dir.path(), container, &why);
    if (path.empty()) continue;  // reported by the test above
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string damaged = (dir.path() / ("damaged" + fs::path(path).extension().string())).string();
    FrameSourceOptions options;
    options.topic = "/cam/image_raw";
    const auto read_damaged = [&](const std::string& content) -> long {
      std::ofstream(damaged, std::ios::binary | std::ios::trunc) << content;
      try {
        return static_cast<long>(ReadAll(damaged, options).size());
      } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find(damaged), std::string::npos) << error.what();
        return -1;
      }
    };
    const long half = read_damaged(bytes.substr(0, bytes.size() * 6 / 10));
    EXPECT_LT(half, kFrames);
    EXPECT_EQ(read_damaged(bytes.substr(0, 40)), -1);
    cv::RNG rng(container.compression.size() * 7 + container.name.size());
    for (int trial = 0; trial < 60; ++trial) {
      std::string corrupt = bytes;
      const size_t at = rng.uniform(0, static_cast<int>(bytes.size() - 4));
      for (int k = 0; k < 4; ++k) corrupt[at + k] = static_cast<char>(trial % 2 ? 0xff : rng.uniform(0, 256));
      EXPECT_LE(read_damaged(corrupt), kFrames);
    }
  }
}

// rosbag2's zstd compression: a damaged compressed database or message is an InputError naming the file, and
// the decompressed copy of a `--compression-mode file` database is gone once the source is.
TEST(RecordingSource, CompressedRosbag2IsDecompressedOutOfTheWayAndDamageNamed) {
  testing::ScopedTempDir dir("rosbag2_zstd");
  const fs::path tmp = dir.path() / "tmp";
  fs::create_directories(tmp);
  const char* old_tmpdir = std::getenv("TMPDIR");
  const std::string saved = old_tmpdir ? old_tmpdir : "";
  setenv("TMPDIR", tmp.c_str(), 1);
  FrameSourceOptions options;
  options.topic = "/cam/image_raw";
  {
    testing::WriteRosbag2((dir.path() / "file").string(), Messages(MessageEncoding::kCdr), "file");
    std::unique_ptr<FrameSource> source = OpenFrameSource((dir.path() / "file").string(), options);
    long frames = 0;
    while (source->Next()) ++frames;
    EXPECT_EQ(frames, kFrames);
    EXPECT_FALSE(fs::is_empty(tmp));  // the copy sqlite reads
  }
  EXPECT_TRUE(fs::is_empty(tmp));
  const fs::path packed = dir.path() / "file" / "file_0.db3.zstd";
  fs::resize_file(packed, fs::file_size(packed) / 2);
  std::string error = ErrorOf([&] { ReadAll((dir.path() / "file").string(), options); });
  EXPECT_NE(error.find("file_0.db3.zstd"), std::string::npos) << error;
  EXPECT_TRUE(fs::is_empty(tmp));

  // A message whose zstd frame is cut short: the first on /cam/image_raw (row 1 is the camera_info).
  std::vector<testing::TestMessage> messages = Messages(MessageEncoding::kCdr);
  testing::WriteRosbag2((dir.path() / "message").string(), messages, "message");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir.path() / "message" / "message_0.db3").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE messages SET data = substr(data, 1, length(data) / 2) WHERE id = 2", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  // As any damage: the frames before it, or an error naming the file.
  long frames = -1;
  error = ErrorOf([&] { frames = static_cast<long>(ReadAll((dir.path() / "message").string(), options).size()); });
  if (error.empty()) {
    EXPECT_LT(frames, kFrames);
  } else {
    EXPECT_NE(error.find("message_0.db3"), std::string::npos) << error;
  }
  if (old_tmpdir)
    setenv("TMPDIR", saved.c_str(), 1);
  else
    unsetenv("TMPDIR");
}

}  // namespace
}  // namespace vmap
