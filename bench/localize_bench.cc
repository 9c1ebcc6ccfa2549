// Speed of `vmap localize` (docs/measurements/localization.md): tracking frames per second with ORB at 640x480 beside
// decode-only and decode + ORB on one thread, and the time of one relocalization against a map of about
// 300 key images. Each repeat measures the stages one after the other, so that the machine's changing load
// touches them alike; the medians and ranges are printed.
//
//   localize_bench [--repeat N]
//
// Tracking: a map of ../shared/data/lab_floor/lab_floor.mp4 (default options), the same video localized
// against it (the repeat run is the teach run: what is measured is the work per frame while tracking).
// Relocalization: a map whose key images are every third frame of ../shared/data/redkitchen (frames 0-899,
// tau 1.0 makes every frame a key image), queried with frames between them, the estimate reset before each.

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
#include "vmap/features/matcher_registry.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/recorded_options.h"

#include "cpu_time.h"

namespace fs = std::filesystem;
using namespace vmap;
using Clock = std::chrono::steady_clock;

namespace {

struct Samples {
  std::vector<double> values;
  double Median() const { return vmap::Median(values); }
  double Min() const { return values.empty() ? 0.0 : *std::min_element(values.begin(), values.end()); }
  double Max() const { return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end()); }
};

void BuildInto(const std::string& input, FrameSourceOptions source_options, double tau, const fs::path& directory) {
  const auto matcher = CreateMatcher({});
  MapBuilderOptions options;
  options.key_images.tau = tau;
  options.show_progress = false;
  fs::create_directories(directory);
  auto source = OpenFrameSource(input, source_options);
  const VisualMap map =
      BuildMap(*source, *matcher, options, directory, DescribeMapOptions(*matcher, options, source_options));
  WriteMapFiles(map, directory);
}

// CPU seconds of the whole process, and of the calling thread: unlike wall time, they hardly change with
// the load other programs put on the machine.
}  // namespace

int main(int argc, char** argv) {
  int repeat = 5;
  for (int i = 1; i + 1 < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeat")) repeat = std::atoi(argv[++i]);
  }
  const std::string shared = VMAP_SHARED_DIR;
  const std::string video = shared + "/data/lab_floor/lab_floor.mp4";
  const std::string kitchen = shared + "/data/redkitchen";
  if (!fs::exists(video) || !fs::exists(kitchen)) {
    std::fprintf(stderr, "localize_bench: ../shared/data is missing\n");
    return 2;
  }
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  const fs::path work = fs::temp_directory_path() / ("vmap_localize_bench_" + std::to_string(getpid()));
  fs::remove_all(work);
  BuildInto(video, {}, 0.5, work / "lab_floor");
  FrameSourceOptions every_third;
  every_third.stride = 3;
  every_third.last = 899;
  BuildInto(kitchen, every_third, 1.0, work / "kitchen300");

  LocalizationMap lab = OpenLocalizationMap(work / "lab_floor", {});
  LocalizationMap kitchen_map = OpenLocalizationMap(work / "kitchen300", {});
  std::printf("tracking map: %zu key images of lab_floor.mp4 (640x480); relocalization map: %zu key images\n",
              lab.map.key_images.size(), kitchen_map.map.key_images.size());

  // track[0]: every comparison on the localizer's thread; track[1]: the workers compare ahead (the default).
  Samples decode, extract, track[2], relocalize_median, relocalize_max;
  Samples extract_cpu, track_cpu[2], track_main_cpu[2], relocalize_cpu;  // milliseconds per frame
  long tracked = 0, frames = 0, relocalized = 0, queries = 0;
  for (int r = 0; r < repeat; ++r) {
    {  // decode only
      auto source = OpenFrameSource(video);
      const auto start = Clock::now();
      long n = 0;
      while (source->Next()) ++n;
      decode.values.push_back(n / std::chrono::duration<double>(Clock::now() - start).count());
    }
    {  // decode + ORB, one thread
      auto source = OpenFrameSource(video);
      const auto start = Clock::now();
      const double cpu = vmap::bench::ProcessCpuSeconds();
      long n = 0;
      while (auto frame = source->Next()) {
        lab.matcher->Extract(frame->gray);
        ++n;
      }
      extract.values.push_back(n / std::chrono::duration<double>(Clock::now() - start).count());
      extract_cpu.values.push_back(1000 * (vmap::bench::ProcessCpuSeconds() - cpu) / n);
    }
    for (bool ahead : {false, true}) {  // vmap localize end to end: decode and extraction on the workers
      auto source = OpenFrameSource(video);
      Localizer localizer(lab.map, lab.keys, *lab.matcher, MapLocalizerOptions(lab));
      LocalizeSequenceOptions options;
      options.show_progress = false;
      options.compare_ahead = ahead;
      const double cpu = vmap::bench::ProcessCpuSeconds(), main_cpu = vmap::bench::ThreadCpuSeconds();
      const LocalizationSummary s = LocalizeSequence(*source, *lab.matcher, localizer, options, nullptr);
      track[ahead].values.push_back(s.frames_per_second);
      track_cpu[ahead].values.push_back(1000 * (vmap::bench::ProcessCpuSeconds() - cpu) / s.frames);
      track_main_cpu[ahead].values.push_back(1000 * (vmap::bench::ThreadCpuSeconds() - main_cpu) / s.frames);
      tracked += s.tracking;
      frames += s.frames;
    }
    {  // relocalization from scratch against the 300-key map
      FrameSourceOptions between = every_third;
      between.first = 1;
      between.stride = 15;
      auto source = OpenFrameSource(kitchen, between);
      Localizer localizer(kitchen_map.map, kitchen_map.keys, *kitchen_map.matcher, MapLocalizerOptions(kitchen_map));
      Samples seconds, cpu_seconds;
      while (auto frame = source->Next()) {
        const auto features = kitchen_map.matcher->Extract(frame->gray);
        localizer.Reset();
        const double cpu = vmap::bench::ThreadCpuSeconds();
        const LocalizationResult result = localizer.Localize(*frame, *features);
        cpu_seconds.values.push_back(vmap::bench::ThreadCpuSeconds() - cpu);
        seconds.values.push_back(result.seconds);
        relocalized += result.status == LocalizationStatus::kRelocalized;
        ++queries;
      }
      relocalize_median.values.push_back(seconds.Median());
      relocalize_cpu.values.push_back(1000 * cpu_seconds.Median());
      relocalize_max.values.push_back(seconds.Max());
    }
  }
  std::printf("| stage | median [range] |\n|---|---|\n");
  std::printf("| decode only (one thread), frames/s | %.0f [%.0f-%.0f] |\n", decode.Median(), decode.Min(),
              decode.Max());
  std::printf("| decode + ORB (one thread), frames/s | %.0f [%.0f-%.0f] |\n", extract.Median(), extract.Min(),
              extract.Max());
  const char* variant[2] = {"comparisons on the localizer thread", "workers compare ahead (default)"};
  for (int a = 0; a < 2; ++a) {
    std::printf("| vmap localize, tracking, %s, frames/s | %.0f [%.0f-%.0f] |\n", variant[a], track[a].Median(),
                track[a].Min(), track[a].Max());
  }
  std::printf("| relocalization, 300-key map, median s per frame | %.3f [%.3f-%.3f] |\n", relocalize_median.Median(),
              relocalize_median.Min(), relocalize_median.Max());
  std::printf("| relocalization, slowest frame of a repeat, s | %.3f [%.3f-%.3f] |\n", relocalize_max.Median(),
              relocalize_max.Min(), relocalize_max.Max());
  std::printf("| decode + ORB (one thread), CPU ms per frame | %.1f [%.1f-%.1f] |\n", extract_cpu.Median(),
              extract_cpu.Min(), extract_cpu.Max());
  for (int a = 0; a < 2; ++a) {
    std::printf("| vmap localize, tracking, %s, CPU ms per frame: all threads | %.1f [%.1f-%.1f] |\n", variant[a],
                track_cpu[a].Median(), track_cpu[a].Min(), track_cpu[a].Max());
    std::printf("| vmap localize, tracking, %s, CPU ms per frame: localizer thread | %.1f [%.1f-%.1f] |\n", variant[a],
                track_main_cpu[a].Median(), track_main_cpu[a].Min(), track_main_cpu[a].Max());
  }
  std::printf("| relocalization, 300-key map, median CPU ms per frame | %.1f [%.1f-%.1f] |\n", relocalize_cpu.Median(),
              relocalize_cpu.Min(), relocalize_cpu.Max());
  std::printf("tracking share %.1f%%; relocalized %ld of %ld queries\n", 100.0 * tracked / std::max(1L, frames),
              relocalized, queries);
  fs::remove_all(work);
  return 0;
}
