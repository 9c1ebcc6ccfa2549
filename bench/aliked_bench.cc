// Timing of ALIKED through the Matcher interface: per-image extraction and per-pair matching at 640x480 and at
// KITTI size (1226x370), with one and two LibTorch threads, ALIKED-T16 and -N16; optionally the deformable
// convolution against a grid_sample-per-tap variant, and `vmap build` end to end next to ORB.
//
//   aliked_bench [--model t16|n16|all] [--reps N] [--stages] [--dcn] [--build [--frames N]] [--no-tune-malloc]
//
// --stages splits one-thread extraction into the network, DKD and SDDH (CPU seconds).
// Every figure is the median of N runs after one warm-up. The build rows run BuildMap as `vmap build` does
// (one extraction worker per core, one LibTorch thread per call) on ../shared/data/lab_floor/lab_floor.mp4.

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <torch/torch.h>

#include "vmap/core/numeric.h"
#include "vmap/core/runtime.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/neural/aliked/aliked_matcher.h"
#include "vmap/neural/aliked/aliked_model.h"
#include "vmap/neural/aliked/aliked_weights.h"
#include "vmap/neural/aliked/deform_conv.h"
#include "vmap/sources/frame_source.h"

#include "cpu_time.h"
#include "wall_time.h"

namespace {

using vmap::Median;
using vmap::bench::TimeSeconds;

// CPU seconds of the whole process (all threads): on a loaded machine this moves much less than wall time.
template <typename F>
double CpuSeconds(F&& f) {
  const double start = vmap::bench::ProcessCpuSeconds();
  f();
  return vmap::bench::ProcessCpuSeconds() - start;
}

// The alternative it is compared with: one grid_sample per kernel tap gathers the columns.
torch::Tensor DeformConvByGridSample(const torch::Tensor& input, const torch::Tensor& offset,
                                     const torch::Tensor& weight, int64_t padding) {
  namespace F = torch::nn::functional;
  const int64_t k = weight.size(2), h = input.size(2), w = input.size(3);
  const int64_t out_h = offset.size(2), out_w = offset.size(3);
  auto rows = torch::arange(out_h, torch::kFloat32).view({out_h, 1}).expand({out_h, out_w});
  auto cols = torch::arange(out_w, torch::kFloat32).view({1, out_w}).expand({out_h, out_w});
  std::vector<torch::Tensor> taps;
  for (int64_t t = 0; t < k * k; ++t) {
    auto y = rows + double(t / k - padding) + offset[0][2 * t];
    auto x = cols + double(t % k - padding) + offset[0][2 * t + 1];
    auto grid = torch::stack({x / double(w - 1) * 2 - 1, y / double(h - 1) * 2 - 1}, -1).unsqueeze(0);
    taps.push_back(F::grid_sample(input, grid, F::GridSampleFuncOptions().mode(torch::kBilinear).align_corners(true)));
  }
  auto columns = torch::stack(taps, 2).view({input.size(1) * k * k, out_h * out_w});
  return weight.view({weight.size(0), -1}).mm(columns).view({1, weight.size(0), out_h, out_w});
}

void BenchDeformConv(int reps) {
  torch::InferenceMode guard;
  at::set_num_threads(1);
  torch::manual_seed(0);
  std::printf("\ndeformable 3x3 convolution, one thread, CPU ms: gather im2col + one matmul vs grid_sample per tap\n");
  std::printf("%-28s %12s %12s %8s\n", "input -> output", "im2col_ms", "gridsamp_ms", "ratio");
  struct Case {
    int64_t c, o, h, w;
    const char* what;
  };
  // ALIKED-N16 block 3 (1/8) and block 4 (1/32) convolutions at 640x480 and 1248x384 (KITTI padded).
  for (const Case& c : {Case{32, 64, 60, 80, "N16 block3 conv1 640x480"}, Case{64, 64, 60, 80, "N16 block3 conv2"},
                        Case{64, 128, 15, 20, "N16 block4 conv1"}, Case{128, 128, 15, 20, "N16 block4 conv2"},
                        Case{64, 64, 48, 156, "N16 block3 conv2 KITTI"}}) {
    auto input = torch::randn({1, c.c, c.h, c.w});
    auto weight = torch::randn({c.o, c.c, 3, 3});
    auto offset = torch::randn({1, 18, c.h, c.w}) * 3.0;
    std::vector<double> ours, grid;
    for (int r = 0; r < reps + 1; ++r) {
      const double a = CpuSeconds([&] { vmap::neural::DeformConv2d(input, offset, weight, {}, {}, 1); });
      const double b = CpuSeconds([&] { DeformConvByGridSample(input, offset, weight, 1); });
      if (r > 0) ours.push_back(a), grid.push_back(b);
    }
    const double max_diff = (vmap::neural::DeformConv2d(input, offset, weight, {}, {}, 1) -
                             DeformConvByGridSample(input, offset, weight, 1))
                                .abs()
                                .max()
                                .item<double>();
    std::printf("%-28s %12.3f %12.3f %8.2f   (%ld->%ld ch, %ldx%ld; max |diff| %.1e)\n", c.what, 1e3 * Median(ours),
                1e3 * Median(grid), Median(grid) / Median(ours), long(c.c), long(c.o), long(c.w), long(c.h), max_diff);
  }
}

void BenchStages(const std::string& shared, const std::string& which, int reps) {
  torch::InferenceMode guard;
  at::set_num_threads(1);
  std::printf("\none-thread extraction by stage, CPU seconds (median of %d)\n", reps);
  std::printf("%-6s %-9s %10s %10s %10s\n", "model", "size", "network_s", "dkd_s", "sddh_s");
  for (const std::string model : {"t16", "n16"}) {
    if (which != "all" && which != model) continue;
    const std::string path = shared + "/weights/aliked/aliked-" + model + ".pt";
    const auto config = vmap::neural::AlikedPreset(model);
    const vmap::neural::AlikedModel net(config, vmap::neural::ReadAlikedStateDict(path), torch::kCPU);
    for (const auto& [size, dir] :
         {std::pair{"640x480", "rccar_000000_000006"}, std::pair{"1226x370", "kitti07_000010_000014"}}) {
      const cv::Mat gray = cv::imread(shared + "/golden/aliked-n16/" + dir + "/input0.png", cv::IMREAD_GRAYSCALE);
      auto image = torch::from_blob(gray.data, {1, 1, gray.rows, gray.cols}, torch::kUInt8).to(torch::kFloat32) / 255.0;
      std::vector<double> network, dkd, sddh;
      for (int r = 0; r < reps + 1; ++r) {
        vmap::neural::AlikedDenseMaps maps;
        vmap::neural::DkdResult detected;
        const double a = CpuSeconds([&] { maps = net.ExtractDenseMaps(image); });
        const double b = CpuSeconds([&] { detected = vmap::neural::DetectKeypoints(maps.score_map, {}); });
        const double c = CpuSeconds([&] { net.Describe(maps, detected.keypoints); });
        if (r > 0) network.push_back(a), dkd.push_back(b), sddh.push_back(c);
      }
      std::printf("%-6s %-9s %10.4f %10.4f %10.4f\n", model.c_str(), size, Median(network), Median(dkd), Median(sddh));
    }
  }
}

void BenchBuild(const std::string& shared, int frames, int reps) {
  const std::string video = shared + "/data/lab_floor/lab_floor.mp4";
  vmap::FrameSourceOptions source_options;
  source_options.last = frames > 0 ? frames - 1 : -1;
  vmap::MapBuilderOptions options;
  options.show_progress = false;
  std::printf("\nvmap build end to end on %s (%s frames, default options, %d extraction workers, median of %d)\n",
              video.c_str(), frames > 0 ? std::to_string(frames).c_str() : "all", options.ExtractionThreads(), reps);
  struct Entry {
    std::string name;
    std::unique_ptr<vmap::Matcher> matcher;
    std::vector<double> rates;
    long keys = 0;
  };
  std::vector<Entry> entries;
  entries.push_back({"orb", vmap::CreateOrbMatcher({}), {}, 0});
  for (const std::string model : {"t16", "n16"}) {
    vmap::AlikedMatcherOptions aliked;
    aliked.model = model;
    aliked.weights = shared + "/weights/aliked/aliked-" + model + ".pt";
    entries.push_back({"aliked-" + model, vmap::CreateAlikedMatcher(aliked), {}, 0});
  }
  // Interleaved, so that the machine's changing load touches every matcher alike.
  for (int r = 0; r < reps; ++r) {
    for (auto& entry : entries) {
      auto source = vmap::OpenFrameSource(video, source_options);
      const auto directory = std::filesystem::temp_directory_path() / ("aliked_bench_" + std::to_string(getpid()));
      std::filesystem::create_directories(directory);  // BuildMap writes into a folder that exists
      long n = 0;
      const double seconds = TimeSeconds([&] {
        const auto map = vmap::BuildMap(*source, *entry.matcher, options, directory);
        n = map.num_frames;
        entry.keys = static_cast<long>(map.key_images.size());
      });
      std::filesystem::remove_all(directory);
      entry.rates.push_back(double(n) / seconds);
    }
  }
  for (const auto& entry : entries) {
    std::printf("%-12s %8.2f frames/s  [%.2f-%.2f]  %ld key images\n", entry.name.c_str(), Median(entry.rates),
                *std::min_element(entry.rates.begin(), entry.rates.end()),
                *std::max_element(entry.rates.begin(), entry.rates.end()), entry.keys);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string which = "all";
  int reps = 5, frames = 0;
  bool dcn = false, build = false, stages = false, tune_malloc = true;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--model") && i + 1 < argc)
      which = argv[++i];
    else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc)
      reps = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
      frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--dcn"))
      dcn = true;
    else if (!std::strcmp(argv[i], "--build"))
      build = true;
    else if (!std::strcmp(argv[i], "--stages"))
      stages = true;
    else if (!std::strcmp(argv[i], "--no-tune-malloc"))
      tune_malloc = false;
    else {
      std::fprintf(stderr,
                   "usage: %s [--model t16|n16|all] [--reps N] [--stages] [--dcn] [--build [--frames N]]"
                   " [--no-tune-malloc]\n",
                   argv[0]);
      return 2;
    }
  }
  // As the vmap binary has the process (core/runtime.h); --no-tune-malloc measures what the malloc setting saves.
  vmap::RuntimeOptions runtime;
  runtime.keep_freed_memory = tune_malloc;
  vmap::InitializeRuntime(runtime);
  const std::string shared = VMAP_SHARED_DIR;
  struct Pair {
    const char* size;
    std::string dir;
  };
  const std::vector<Pair> pairs{{"640x480", shared + "/golden/aliked-n16/rccar_000000_000006"},
                                {"1226x370", shared + "/golden/aliked-n16/kitti07_000010_000014"}};
  std::printf("%-6s %-9s %7s %6s %10s %10s %10s %10s %6s %8s\n", "model", "size", "threads", "reps", "extract_s",
              "cpu_s", "match_s", "frame_s", "kpts", "matches");
  for (const std::string model : {"t16", "n16"}) {
    if (which != "all" && which != model) continue;
    for (const auto& pair : pairs) {
      const cv::Mat image0 = cv::imread(pair.dir + "/input0.png", cv::IMREAD_GRAYSCALE);
      const cv::Mat image1 = cv::imread(pair.dir + "/input1.png", cv::IMREAD_GRAYSCALE);
      if (image0.empty() || image1.empty()) {
        std::fprintf(stderr, "cannot read the pair under %s\n", pair.dir.c_str());
        return 1;
      }
      for (int threads : {1, 2}) {
        vmap::AlikedMatcherOptions options;
        options.model = model;
        options.weights = shared + "/weights/aliked/aliked-" + model + ".pt";
        options.num_threads = threads;
        const auto matcher = vmap::CreateAlikedMatcher(options);
        auto key = matcher->Extract(image0);  // warm-up
        auto frame = matcher->Extract(image1);
        size_t matches = matcher->Match(*key, *frame).size();
        std::vector<double> extract_s, cpu_s, match_s, frame_s;
        for (int r = 0; r < reps; ++r) {
          cpu_s.push_back(
              CpuSeconds([&] { extract_s.push_back(TimeSeconds([&] { frame = matcher->Extract(image1); })); }));
          match_s.push_back(TimeSeconds([&] { matches = matcher->Match(*key, *frame).size(); }));
          frame_s.push_back(extract_s.back() + match_s.back());
        }
        std::printf("%-6s %-9s %7d %6d %10.4f %10.4f %10.4f %10.4f %6d %8zu\n", model.c_str(), pair.size, threads, reps,
                    Median(extract_s), Median(cpu_s), Median(match_s), Median(frame_s), frame->num_features(), matches);
        std::fflush(stdout);
      }
    }
  }
  if (stages) BenchStages(shared, which, reps);
  if (dcn) BenchDeformConv(std::max(reps, 10));
  if (build) BenchBuild(shared, frames, std::max(1, std::min(reps, 3)));
  return 0;
}
