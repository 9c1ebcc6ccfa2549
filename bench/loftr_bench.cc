// Timing of LoFTR through the Matcher interface: per pair (both images extracted, then matched) and per
// frame with the key image's features cached (one extraction and one match), at 640x480 and 320x240.
//
//   loftr_bench [--model coarse|outdoor|all] [--reps N] [--no-tune-malloc] [--threads N]
//
// The full model uses the golden's random weights with threshold 0 so that the fine stage runs on every
// mutual-nearest-neighbour pair (random weights pass no real threshold); speed does not depend on the values.

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <torch/torch.h>

#include "vmap/core/numeric.h"
#include "vmap/core/runtime.h"
#include "vmap/neural/loftr/loftr_matcher.h"

#include "wall_time.h"

namespace {

using vmap::Median;
using vmap::bench::TimeSeconds;

}  // namespace

int main(int argc, char** argv) {
  std::string which = "all";
  int reps = 0;
  bool tune_malloc = true;
  int threads = 0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--model") && i + 1 < argc)
      which = argv[++i];
    else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc)
      reps = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-tune-malloc"))
      tune_malloc = false;
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr, "usage: %s [--model coarse|outdoor|all] [--reps N] [--no-tune-malloc] [--threads N]\n",
                   argv[0]);
      return 2;
    }
  }
  // As the vmap binary has the process (core/runtime.h); --no-tune-malloc measures what the malloc setting saves.
  vmap::RuntimeOptions runtime;
  runtime.keep_freed_memory = tune_malloc;
  vmap::InitializeRuntime(runtime);
  const std::string shared = VMAP_SHARED_DIR;
  const std::string pair = shared + "/golden/loftr_coarse/rccar_000000_000006";
  const cv::Mat image0 = cv::imread(pair + "/input0.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat image1 = cv::imread(pair + "/input1.png", cv::IMREAD_GRAYSCALE);
  if (image0.empty() || image1.empty()) {
    std::fprintf(stderr, "cannot read the rccar pair under %s\n", pair.c_str());
    return 1;
  }
  if (threads > 0) torch::set_num_threads(threads);
  std::printf("torch threads %d, malloc tuning %s, GLIBC_TUNABLES=%s\n", torch::get_num_threads(),
              tune_malloc ? "on" : "off", std::getenv("GLIBC_TUNABLES") ? std::getenv("GLIBC_TUNABLES") : "");
  std::printf("%-8s %-8s %6s %12s %12s %10s %10s %8s\n", "model", "size", "reps", "pair_s", "frame_s", "extract_s",
              "match_s", "matches");
  for (const std::string model : {"coarse", "outdoor"}) {
    if (which != "all" && which != model) continue;
    for (const cv::Size size : {cv::Size(640, 480), cv::Size(320, 240)}) {
      vmap::LoftrMatcherOptions options;
      options.model = model;
      options.longest_side = size.width;
      options.num_threads = threads;
      if (model == "coarse") {
        options.weights = shared + "/weights/loftr_coarse/loftr_coarse_teacher.pt";
      } else {
        options.weights = shared + "/golden/loftr_full_random/weights_fp16.pt";
        options.threshold = 0.0;
      }
      const auto matcher = vmap::CreateLoftrMatcher(options);
      cv::Mat a, b;
      cv::resize(image0, a, size, 0, 0, cv::INTER_AREA);
      cv::resize(image1, b, size, 0, 0, cv::INTER_AREA);
      const int n = reps > 0 ? reps : (model == "coarse" ? 30 : 3);
      // Warm-up: first-call allocations and thread-pool start.
      auto key = matcher->Extract(a);
      size_t num_matches = matcher->Match(*key, *matcher->Extract(b)).size();
      std::vector<double> pair_s, frame_s, extract_s, match_s;
      for (int r = 0; r < n; ++r) {
        pair_s.push_back(TimeSeconds([&] {
          auto f0 = matcher->Extract(a);
          auto f1 = matcher->Extract(b);
          num_matches = matcher->Match(*f0, *f1).size();
        }));
        std::shared_ptr<const vmap::ImageFeatures> frame;
        extract_s.push_back(TimeSeconds([&] { frame = matcher->Extract(b); }));
        match_s.push_back(TimeSeconds([&] { matcher->Match(*key, *frame); }));
        frame_s.push_back(extract_s.back() + match_s.back());
      }
      std::printf("%-8s %4dx%-3d %6d %12.4f %12.4f %10.4f %10.4f %8zu\n", model.c_str(), size.width, size.height, n,
                  Median(pair_s), Median(frame_s), Median(extract_s), Median(match_s), num_matches);
      std::fflush(stdout);
    }
  }
  return 0;
}
