// Frames per second of `vmap build` (ORB + MAGSAC) on a video, next to decode-only and decode + ORB
// detection, all measured in the same run so the figures compare.
//
//   build_bench [VIDEO] [--repeat N]     (default: ../shared/data/lab_floor/lab_floor.mp4, 3 repeats)
//
// Prints the median of the repeats for each stage.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/map_builder.h"
#include "vmap/sources/frame_source.h"

namespace {

using Clock = std::chrono::steady_clock;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

template <typename Fn>
double FramesPerSecond(int repeat, Fn&& run) {
  std::vector<double> rates;
  for (int r = 0; r < repeat; ++r) {
    const auto start = Clock::now();
    const long frames = run();
    rates.push_back(frames / std::chrono::duration<double>(Clock::now() - start).count());
  }
  return Median(rates);
}

}  // namespace

int main(int argc, char** argv) {
  std::string video = std::string(VMAP_SHARED_DIR) + "/data/lab_floor/lab_floor.mp4";
  int repeat = 3;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else video = argv[i];
  }
  if (!std::filesystem::exists(video)) {
    std::fprintf(stderr, "build_bench: '%s' not found; pass a video path\n", video.c_str());
    return 2;
  }
  cv::setNumThreads(1);  // as the vmap binary does: vmap parallelises across frames itself
  const auto matcher = vmap::CreateOrbMatcher({});

  const double decode = FramesPerSecond(repeat, [&] {
    auto source = vmap::OpenFrameSource(video);
    long n = 0;
    while (source->Next()) ++n;
    return n;
  });
  const double detect = FramesPerSecond(repeat, [&] {
    auto source = vmap::OpenFrameSource(video);
    long n = 0;
    while (auto frame = source->Next()) {
      matcher->Extract(frame->gray);
      ++n;
    }
    return n;
  });
  vmap::MapBuilderOptions options;
  options.show_progress = false;
  long key_images = 0;
  const double build = FramesPerSecond(repeat, [&] {
    auto source = vmap::OpenFrameSource(video);
    // Key images are written as in `vmap build`: that is part of the work.
    const std::filesystem::path directory =
        std::filesystem::temp_directory_path() / ("build_bench_" + std::to_string(getpid()));
    const vmap::VisualMap map = vmap::BuildMap(*source, *matcher, options, directory);
    std::filesystem::remove_all(directory);
    key_images = static_cast<long>(map.key_images.size());
    return static_cast<long>(map.num_frames);
  });

  std::printf("video: %s (median of %d runs)\n", video.c_str(), repeat);
  std::printf("%-40s %8.1f frames/s\n", "decode only", decode);
  std::printf("%-40s %8.1f frames/s\n", "decode + ORB detection (one thread)", detect);
  std::printf("%-40s %8.1f frames/s  (%ld key images, tau %.2f)\n", "vmap build (ORB + MAGSAC, end to end)", build,
              key_images, options.key_images.tau);
  std::printf("build / (decode + detection) = %.2f\n", build / detect);
  return 0;
}
