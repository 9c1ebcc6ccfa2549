// Timing of XFeat: per image (detectAndCompute through the Matcher interface) and per pair (matching two
// images' descriptors) at 640x480 and at KITTI size (1226x370), on one and two LibTorch threads; the
// network and the post-processing apart; the same detectAndCompute with upstream's LibTorch ops instead of
// vmap's CPU paths (measured interleaved, for the ratio); and `vmap build` frames/s end to end on a video,
// next to ORB; with --float-matching, MatchFloatDescriptors against every pair's similarity
// (MatchFloatDescriptorsExhaustively) on XFeat's descriptors of real pairs, interleaved.
//
//   xfeat_bench [--reps N] [--top-k K ...] [--threads N ...] [--build [VIDEO]] [--build-repeat N] [--frames N]
//               [--float-matching]
//
// Without --build it times images; with --build it only times the builds. Median of N runs after a warm-up.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <torch/torch.h>

#include "vmap/core/numeric.h"
#include "vmap/core/runtime.h"
#include "vmap/features/float_matcher.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/neural/xfeat/xfeat_matcher.h"
#include "vmap/neural/xfeat/xfeat_model.h"
#include "vmap/neural/xfeat/xfeat_weights.h"
#include "vmap/sources/frame_source.h"

#include "wall_time.h"

namespace {

using Clock = std::chrono::steady_clock;

using vmap::Median;
using vmap::bench::TimeSeconds;

struct Pair {
  std::string name;
  cv::Mat image0, image1;
};

void TimeImages(const std::string& weights, const std::vector<Pair>& pairs, const std::vector<int>& top_ks,
                const std::vector<int>& thread_counts, int reps) {
  std::printf("%-9s %7s %7s %6s %10s %10s %10s %10s %10s %8s %8s\n", "image", "threads", "top_k", "reps", "extract_s",
              "network_s", "post_s", "upstream_s", "match_s", "kpts", "matches");
  const auto folded = vmap::neural::LoadXfeatWeights(weights).folded;
  const vmap::neural::XfeatModel model(folded, torch::kCPU);
  for (const Pair& pair : pairs) {
    for (int threads : thread_counts) {
      for (int top_k : top_ks) {
        vmap::XfeatMatcherOptions options;
        options.weights = weights;
        options.top_k = top_k;
        options.num_threads = threads;
        const auto matcher = vmap::CreateXfeatMatcher(options);
        torch::set_num_threads(threads);
        // The network alone, on the same input as Extract gives it.
        const cv::Mat& gray = pair.image0;
        const auto input =
            torch::from_blob(gray.data, {1, 1, gray.rows, gray.cols}, torch::kUInt8).to(torch::kFloat32).div_(255.0);
        const auto net_input = torch::upsample_bilinear2d(input, {gray.rows / 32 * 32, gray.cols / 32 * 32}, false);
        auto f0 = matcher->Extract(pair.image0);  // warm-up
        auto f1 = matcher->Extract(pair.image1);
        size_t matches = matcher->Match(*f0, *f1).size();
        vmap::neural::XfeatDetectOptions upstream_ops;
        upstream_ops.top_k = top_k;
        upstream_ops.upstream_network_ops = upstream_ops.upstream_postprocessing_ops = true;
        std::vector<double> extract_s, network_s, upstream_s, match_s;
        for (int r = 0; r < reps; ++r) {
          extract_s.push_back(TimeSeconds([&] { f0 = matcher->Extract(pair.image0); }));
          network_s.push_back(TimeSeconds([&] {
            torch::InferenceMode guard;
            model.Forward(net_input);
          }));
          upstream_s.push_back(TimeSeconds([&] { model.DetectAndCompute(input, upstream_ops); }));
          match_s.push_back(TimeSeconds([&] { matches = matcher->Match(*f0, *f1).size(); }));
        }
        const double extract = Median(extract_s), network = Median(network_s);
        std::printf("%-9s %7d %7d %6d %10.4f %10.4f %10.4f %10.4f %10.4f %8d %8zu\n", pair.name.c_str(), threads, top_k,
                    reps, extract, network, extract - network, Median(upstream_s), Median(match_s), f0->num_features(),
                    matches);
        std::fflush(stdout);
      }
    }
  }
}

void TimeBuilds(const std::string& weights, const std::string& video, const std::vector<int>& top_ks, int repeat,
                int frames) {
  vmap::FrameSourceOptions source_options;
  source_options.last = frames - 1;  // -1: the whole video
  vmap::MapBuilderOptions options;
  options.show_progress = false;
  std::vector<std::pair<std::string, std::unique_ptr<vmap::Matcher>>> matchers;
  matchers.emplace_back("orb", vmap::CreateOrbMatcher({}));
  for (int top_k : top_ks) {
    vmap::XfeatMatcherOptions xfeat;
    xfeat.weights = weights;
    xfeat.top_k = top_k;
    matchers.emplace_back("xfeat top_k " + std::to_string(top_k), vmap::CreateXfeatMatcher(xfeat));
  }
  std::vector<std::vector<double>> rates(matchers.size());
  std::vector<size_t> key_images(matchers.size());
  // Matchers alternate within each repeat, so that the machine's changing load touches them alike.
  for (int r = 0; r < repeat; ++r) {
    for (size_t m = 0; m < matchers.size(); ++m) {
      auto source = vmap::OpenFrameSource(video, source_options);
      const auto directory = std::filesystem::temp_directory_path() / ("xfeat_bench_" + std::to_string(getpid()));
      std::filesystem::create_directories(directory);  // BuildMap writes into a folder that exists
      const auto start = Clock::now();
      const vmap::VisualMap map = vmap::BuildMap(*source, *matchers[m].second, options, directory);
      rates[m].push_back(map.num_frames / std::chrono::duration<double>(Clock::now() - start).count());
      std::filesystem::remove_all(directory);
      key_images[m] = map.key_images.size();
    }
  }
  std::printf("vmap build on %s, default options (tau %.2f), median of %d [min-max]\n", video.c_str(),
              options.key_images.tau, repeat);
  for (size_t m = 0; m < matchers.size(); ++m) {
    std::printf("%-20s %8.1f frames/s [%.1f-%.1f]  %zu key images\n", matchers[m].first.c_str(), Median(rates[m]),
                *std::min_element(rates[m].begin(), rates[m].end()),
                *std::max_element(rates[m].begin(), rates[m].end()), key_images[m]);
  }
}

// The pairs a tracking frame and a key image make (lab_floor, frames 10, 30 and 60 apart) and those of
// another season (michigan_seasons, the same place a season apart), XFeat's 4096 keypoints, its 0.82 floor.
void TimeFloatMatching(const std::string& weights, const std::string& shared, int reps) {
  torch::set_num_threads(1);
  const auto folded = vmap::neural::LoadXfeatWeights(weights).folded;
  const vmap::neural::XfeatModel model(folded, torch::kCPU);
  vmap::neural::XfeatDetectOptions detect;
  auto descriptors = [&](const cv::Mat& gray) {
    torch::InferenceMode guard;
    const auto input =
        torch::from_blob(gray.data, {1, 1, gray.rows, gray.cols}, torch::kUInt8).to(torch::kFloat32).div_(255.0);
    const torch::Tensor rows = model.DetectAndCompute(input, detect).descriptors.contiguous();
    return cv::Mat(static_cast<int>(rows.size(0)), 64, CV_32F, rows.data_ptr<float>()).clone();
  };
  std::vector<std::pair<std::string, std::pair<cv::Mat, cv::Mat>>> pairs;
  vmap::FrameSourceOptions source_options;
  source_options.last = 120;
  auto source = vmap::OpenFrameSource(shared + "/data/lab_floor/lab_floor.mp4", source_options);
  std::vector<cv::Mat> frames;
  while (auto frame = source->Next()) frames.push_back(frame->gray.clone());
  for (int first : {0, 60}) {
    for (int apart : {10, 30, 60}) {
      pairs.push_back({"lab_floor " + std::to_string(first) + "-" + std::to_string(first + apart),
                       {descriptors(frames[first]), descriptors(frames[first + apart])}});
    }
  }
  const std::string seasons = shared + "/data/michigan_seasons/images/";
  for (const auto& [a, b] : std::vector<std::pair<std::string, std::string>>{{"0101", "0601"}, {"0302", "1102"}}) {
    pairs.push_back({"michigan " + a + "-" + b,
                     {descriptors(cv::imread(seasons + a + ".png", cv::IMREAD_GRAYSCALE)),
                      descriptors(cv::imread(seasons + b + ".png", cv::IMREAD_GRAYSCALE))}});
  }
  std::printf("%-22s %6s %6s %8s %8s %14s %10s %7s\n", "pair", "rows", "cols", "matches", "same", "exhaustive_ms",
              "bound_ms", "ratio");
  for (const auto& [name, pair] : pairs) {
    const auto& [query, train] = pair;
    const auto exhaustive = vmap::MatchFloatDescriptorsExhaustively(query, train, 0.82f);
    const auto bounded = vmap::MatchFloatDescriptors(query, train, 0.82f);
    size_t same = 0;
    for (size_t k = 0; k < std::min(exhaustive.size(), bounded.size()); ++k) {
      same += exhaustive[k].query == bounded[k].query && exhaustive[k].train == bounded[k].train;
    }
    std::vector<double> exhaustive_s, bounded_s;
    for (int r = 0; r < reps; ++r) {
      exhaustive_s.push_back(TimeSeconds([&] { vmap::MatchFloatDescriptorsExhaustively(query, train, 0.82f); }));
      bounded_s.push_back(TimeSeconds([&] { vmap::MatchFloatDescriptors(query, train, 0.82f); }));
    }
    std::printf("%-22s %6d %6d %8zu %8zu %14.2f %10.2f %7.2f\n", name.c_str(), query.rows, train.rows,
                exhaustive.size(), same, 1e3 * Median(exhaustive_s), 1e3 * Median(bounded_s),
                Median(exhaustive_s) / Median(bounded_s));
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string shared = VMAP_SHARED_DIR;
  int reps = 20, build_repeat = 3, frames = 0;
  std::vector<int> top_ks, thread_counts;
  std::string video;
  bool float_matching = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc)
      reps = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--top-k") && i + 1 < argc)
      top_ks.push_back(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      thread_counts.push_back(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--build-repeat") && i + 1 < argc)
      build_repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
      frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--float-matching"))
      float_matching = true;
    else if (!std::strcmp(argv[i], "--build")) {
      video = (i + 1 < argc && argv[i + 1][0] != '-') ? argv[++i] : shared + "/data/lab_floor/lab_floor.mp4";
    } else {
      std::fprintf(stderr,
                   "usage: %s [--reps N] [--top-k K ...] [--threads N ...] [--build [VIDEO]] [--build-repeat N] "
                   "[--frames N] [--float-matching]\n",
                   argv[0]);
      return 2;
    }
  }
  if (top_ks.empty()) top_ks = {4096};
  if (thread_counts.empty()) thread_counts = {1, 2};
  const std::string weights = shared + "/weights/xfeat/xfeat_folded.pt";
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  if (float_matching) {
    TimeFloatMatching(weights, shared, reps);
    return 0;
  }
  if (!video.empty()) {
    TimeBuilds(weights, video, top_ks, build_repeat, frames);
    return 0;
  }
  auto read = [&](const std::string& path) {
    cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (m.empty()) {
      std::fprintf(stderr, "cannot read %s\n", path.c_str());
      std::exit(1);
    }
    return m;
  };
  const std::string golden = shared + "/golden/xfeat/";
  const std::vector<Pair> pairs{
      {"640x480", read(golden + "rccar_000000_000006/input0.png"), read(golden + "rccar_000000_000006/input1.png")},
      {"1226x370", read(golden + "kitti07_000010_000014/input0.png"),
       read(golden + "kitti07_000010_000014/input1.png")}};
  TimeImages(weights, pairs, top_ks, thread_counts, reps);
  return 0;
}
