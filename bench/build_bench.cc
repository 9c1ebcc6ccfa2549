// Frames per second of `vmap build` (ORB + MAGSAC) on a video, next to decode-only and decode + ORB
// detection, all measured in the same run so the figures compare.
//
//   build_bench [VIDEO] [--repeat N]     (default: ../shared/data/lab_floor/lab_floor.mp4, 5 repeats)
//
// Prints the median of the repeats for each stage, and their range.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/numeric.h"
#include "vmap/core/runtime.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/sources/frame_source.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Rates {
  std::vector<double> values;
  double Median() const { return vmap::Median(values); }
  double Min() const { return *std::min_element(values.begin(), values.end()); }
  double Max() const { return *std::max_element(values.begin(), values.end()); }
};

template <typename Fn>
void Measure(Rates* rates, Fn&& run) {
  const auto start = Clock::now();
  const long frames = run();
  rates->values.push_back(frames / std::chrono::duration<double>(Clock::now() - start).count());
}

}  // namespace

int main(int argc, char** argv) {
  std::string video = std::string(VMAP_SHARED_DIR) + "/data/lab_floor/lab_floor.mp4";
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc)
      repeat = std::atoi(argv[++i]);
    else
      video = argv[i];
  }
  if (!std::filesystem::exists(video)) {
    std::fprintf(stderr, "build_bench: '%s' not found; pass a video path\n", video.c_str());
    return 2;
  }
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  const auto matcher = vmap::CreateOrbMatcher({});

  vmap::MapBuilderOptions options;
  options.show_progress = false;
  long key_images = 0;
  // The three stages are measured one after the other within each repeat, so that a change in the machine's
  // load (it is shared) touches all of them alike.
  Rates decode, detect, build;
  for (int r = 0; r < repeat; ++r) {
    Measure(&decode, [&] {
      auto source = vmap::OpenFrameSource(video);
      long n = 0;
      while (source->Next()) ++n;
      return n;
    });
    Measure(&detect, [&] {
      auto source = vmap::OpenFrameSource(video);
      long n = 0;
      while (auto frame = source->Next()) {
        matcher->Extract(frame->gray);
        ++n;
      }
      return n;
    });
    Measure(&build, [&] {
      auto source = vmap::OpenFrameSource(video);
      // Key images are written as in `vmap build`: that is part of the work.
      const std::filesystem::path directory =
          std::filesystem::temp_directory_path() / ("build_bench_" + std::to_string(getpid()));
      std::filesystem::create_directories(directory);  // BuildMap writes into a folder that exists
      const vmap::VisualMap map = vmap::BuildMap(*source, *matcher, options, directory);
      std::filesystem::remove_all(directory);
      key_images = static_cast<long>(map.key_images.size());
      return static_cast<long>(map.num_frames);
    });
  }

  std::printf("video: %s (median of %d runs, [min-max])\n", video.c_str(), repeat);
  auto print = [](const char* stage, const Rates& rates) {
    std::printf("%-40s %8.1f frames/s  [%.1f-%.1f]\n", stage, rates.Median(), rates.Min(), rates.Max());
  };
  print("decode only", decode);
  print("decode + ORB detection (one thread)", detect);
  print("vmap build (ORB + MAGSAC, end to end)", build);
  std::printf("%ld key images at tau %.2f; build / (decode + detection) = %.2f\n", key_images, options.key_images.tau,
              build.Median() / detect.Median());
  return 0;
}
