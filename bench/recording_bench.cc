// How fast vmap reads robot recordings against how fast it builds a map from them (issue: reading must not be
// the bottleneck, >= 2x the build's frame rate). The frames of a video are written as raw bgr8 images into a
// ROS 1 bag (uncompressed and lz4), a rosbag2 sqlite3 folder and MCAP files (uncompressed and zstd); then,
// in each repeat, every recording is read through OpenFrameSource (opening included: the topic scan and the
// camera) and a map is built from the MCAP one (ORB + MAGSAC, as `vmap build`), in the same run.
//
//   recording_bench [VIDEO] [--frames N] [--repeat N]   (default: lab_floor.mp4, 300 frames, 3 repeats)
//   recording_bench [VIDEO] [--frames N] --write DIR    (only writes the recordings into DIR, for timing two
//                                                        vmap binaries on them: bench/hostile_speed.sh)

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "vmap/core/numeric.h"
#include "vmap/core/runtime.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/sources/frame_source.h"
#include "vmap/testing/recording_writer.h"

namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::vector<vmap::testing::TestMessage> Messages(const std::string& video, int frames, vmap::MessageEncoding encoding) {
  vmap::FrameSourceOptions options;
  options.last = frames - 1;
  auto source = vmap::OpenFrameSource(video, options);
  std::vector<vmap::testing::TestMessage> messages;
  while (auto frame = source->Next()) {
    const int64_t ns = 1'000'000'000 + static_cast<int64_t>(frame->index) * 33'333'333;
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", ns,
                        vmap::testing::SerializeImage(encoding, ns * 1e-9, "cam", frame->color, "bgr8")});
  }
  return messages;
}

using vmap::Median;

}  // namespace

int main(int argc, char** argv) {
  std::string video = std::string(VMAP_SHARED_DIR) + "/data/lab_floor/lab_floor.mp4";
  int frames = 300, repeat = 3;
  std::string write_only;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
      frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc)
      repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--write") && i + 1 < argc)
      write_only = argv[++i];
    else
      video = argv[i];
  }
  if (!fs::exists(video)) {
    std::fprintf(stderr, "recording_bench: '%s' not found; pass a video path\n", video.c_str());
    return 2;
  }
  vmap::InitializeRuntime();
  spdlog::set_level(spdlog::level::warn);  // the recordings have no camera_info topic, as intended
  const fs::path dir = write_only.empty() ? fs::temp_directory_path() / ("recording_bench_" + std::to_string(getpid()))
                                          : fs::path(write_only);
  fs::create_directories(dir);
  struct Recording {
    std::string name, path;
    std::vector<double> rates;
  };
  std::vector<Recording> recordings;
  {
    const auto ros2 = Messages(video, frames, vmap::MessageEncoding::kCdr);
    vmap::testing::WriteMcap((dir / "plain.mcap").string(), ros2, "none", 8);
    vmap::testing::WriteMcap((dir / "zstd.mcap").string(), ros2, "zstd", 8);
    vmap::testing::WriteRosbag2((dir / "rosbag2").string(), ros2);
    recordings.push_back({"MCAP, uncompressed chunks", (dir / "plain.mcap").string(), {}});
    recordings.push_back({"MCAP, zstd chunks", (dir / "zstd.mcap").string(), {}});
    recordings.push_back({"rosbag2 sqlite3", (dir / "rosbag2").string(), {}});
    const auto ros1 = Messages(video, frames, vmap::MessageEncoding::kRos1);
    std::string why;
    for (const char* compression : {"none", "lz4"}) {
      const std::string bag = (dir / (std::string(compression) + ".bag")).string();
      if (vmap::testing::WriteRos1Bag(bag, ros1, compression, &why)) {
        recordings.push_back({std::string("ROS 1 bag, ") + compression, bag, {}});
      } else {
        std::fprintf(stderr, "recording_bench: no ROS 1 bags: %s\n", why.c_str());
      }
    }
  }
  if (!write_only.empty()) return 0;
  const auto matcher = vmap::CreateOrbMatcher({});
  vmap::MapBuilderOptions options;
  options.show_progress = false;
  std::vector<double> build_rates;
  long key_images = 0;
  for (int r = 0; r < repeat; ++r) {
    for (Recording& recording : recordings) {
      const auto start = Clock::now();
      auto source = vmap::OpenFrameSource(recording.path);
      long n = 0;
      while (source->Next()) ++n;
      recording.rates.push_back(n / std::chrono::duration<double>(Clock::now() - start).count());
    }
    fs::create_directories(dir / "map");
    const auto start = Clock::now();
    auto source = vmap::OpenFrameSource(recordings[0].path);
    const vmap::VisualMap map = vmap::BuildMap(*source, *matcher, options, dir / "map");
    build_rates.push_back(map.num_frames / std::chrono::duration<double>(Clock::now() - start).count());
    key_images = static_cast<long>(map.key_images.size());
    fs::remove_all(dir / "map");
  }
  const double build = Median(build_rates);
  std::printf("%d frames of %s as bgr8 images (median of %d runs)\n", frames, video.c_str(), repeat);
  for (const Recording& recording : recordings) {
    std::printf("read %-28s %8.1f frames/s  %5.1fx the build's rate  (%.0f MB)\n", recording.name.c_str(),
                Median(recording.rates), Median(recording.rates) / build,
                (fs::is_directory(recording.path) ? fs::file_size(fs::path(recording.path) / "rosbag2_0.db3")
                                                  : fs::file_size(recording.path)) /
                    1e6);
  }
  std::printf("vmap build (ORB + MAGSAC) of the MCAP   %8.1f frames/s  (%ld key images)\n", build, key_images);
  fs::remove_all(dir);
  return 0;
}
