// The threshold sweep against one build, and the sweep's decisions against the paper's exact (exhaustive) run.
//
//   sweep_bench [INPUT] [--thresholds 0.1:0.9:0.1] [--tau 0.5] [--repeat N] [--seeds K] [--no-timing] [--no-flips]
//
// (default input: ../shared/data/rccar_room/images). Three parts, all in this one process:
//  1. Time. Each repeat runs, one after the other: `vmap build` (tau, key images and map files written),
//     `vmap sweep`, `vmap sweep --exhaustive`, `vmap build --exhaustive`. Printed: median wall and CPU seconds
//     (user + system, all threads) and the ratios sweep / build.
//  2. Tables. m and Q per tau of the exhaustive sweep with seeds 0..K-1 and of the default sweep with the same
//     seeds: how far the default sweep is from the paper's tables, next to how far a seed change moves them.
//  3. Decisions. Every comparison S(key, frame) >= tau the exhaustive sweep (seed 0) made is made again on the
//     same pair: by OpenCV with seed 1, and by vmap's early-stopping estimator asked for the taus whose maps
//     compared that pair (as the default sweep asks). Printed per tau: decisions flipped by each.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/numeric.h"
#include "vmap/core/runtime.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/sweep_thresholds.h"
#include "vmap/sources/frame_source.h"

#include "cpu_time.h"

namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Timing {
  std::vector<double> wall, cpu;
};

using vmap::Median;

template <typename Fn>
void Measure(Timing* timing, Fn&& run) {
  const double cpu = vmap::bench::ProcessCpuSeconds();
  const auto start = Clock::now();
  run();
  timing->wall.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  timing->cpu.push_back(vmap::bench::ProcessCpuSeconds() - cpu);
}

vmap::MapBuilderOptions Options(bool exhaustive, int seed) {
  vmap::MapBuilderOptions options;
  options.show_progress = false;
  options.exhaustive = exhaustive;
  options.verifier.seed = seed;
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  std::string input = std::string(VMAP_SHARED_DIR) + "/data/rccar_room/images";
  std::string thresholds = "0.1:0.9:0.1";
  double tau = 0.5;
  int repeat = 3, seeds = 3;
  bool timing = true, flips = true;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--thresholds") && i + 1 < argc)
      thresholds = argv[++i];
    else if (!std::strcmp(argv[i], "--tau") && i + 1 < argc)
      tau = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc)
      repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--seeds") && i + 1 < argc)
      seeds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-timing"))
      timing = false;
    else if (!std::strcmp(argv[i], "--no-flips"))
      flips = false;
    else
      input = argv[i];
  }
  if (!fs::exists(input)) {
    std::fprintf(stderr, "sweep_bench: '%s' not found\n", input.c_str());
    return 2;
  }
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  const auto matcher = vmap::CreateOrbMatcher({});
  const std::vector<double> taus = vmap::ParseThresholds(thresholds);
  const fs::path temp = fs::temp_directory_path() / ("sweep_bench_" + std::to_string(getpid()));
  std::printf("input %s, thresholds %s\n", input.c_str(), thresholds.c_str());

  if (timing) {
    Timing build, sweep, sweep_exhaustive, build_exhaustive;
    auto run_build = [&](bool exhaustive) {
      vmap::MapBuilderOptions options = Options(exhaustive, 0);
      options.key_images.tau = tau;
      auto source = vmap::OpenFrameSource(input);
      fs::create_directory(temp);  // BuildMap writes into an existing folder
      const vmap::VisualMap map = vmap::BuildMap(*source, *matcher, options, temp);
      vmap::WriteMapFiles(map, temp);
      fs::remove_all(temp);
    };
    auto run_sweep = [&](bool exhaustive) {
      auto source = vmap::OpenFrameSource(input);
      vmap::SweepThresholds(*source, *matcher, Options(exhaustive, 0), taus);
    };
    for (int r = 0; r < repeat; ++r) {
      Measure(&build, [&] { run_build(false); });
      Measure(&sweep, [&] { run_sweep(false); });
      Measure(&sweep_exhaustive, [&] { run_sweep(true); });
      Measure(&build_exhaustive, [&] { run_build(true); });
    }
    std::printf("\ntime, median of %d interleaved repeats (wall / CPU seconds)\n", repeat);
    auto row = [](const char* name, const Timing& t) {
      std::printf("  %-32s %7.2f / %7.2f\n", name, Median(t.wall), Median(t.cpu));
    };
    row("vmap build", build);
    row("vmap sweep", sweep);
    row("vmap sweep --exhaustive", sweep_exhaustive);
    row("vmap build --exhaustive", build_exhaustive);
    auto ratio = [](const Timing& a, const Timing& b, bool cpu) {
      std::vector<double> r;
      for (size_t i = 0; i < a.wall.size(); ++i) r.push_back(cpu ? a.cpu[i] / b.cpu[i] : a.wall[i] / b.wall[i]);
      return Median(r);
    };
    std::printf("  sweep / build:                          wall %.2fx, CPU %.2fx\n", ratio(sweep, build, false),
                ratio(sweep, build, true));
    std::printf("  sweep --exhaustive / build --exhaustive: wall %.2fx, CPU %.2fx\n",
                ratio(sweep_exhaustive, build_exhaustive, false), ratio(sweep_exhaustive, build_exhaustive, true));
    std::printf("  sweep --exhaustive / sweep:             wall %.2fx, CPU %.2fx\n",
                ratio(sweep_exhaustive, sweep, false), ratio(sweep_exhaustive, sweep, true));
    std::printf("  sweep / build --exhaustive:             wall %.2fx, CPU %.2fx\n",
                ratio(sweep, build_exhaustive, false), ratio(sweep, build_exhaustive, true));
  }
  if (!flips) return 0;

  // Part 2: tables.
  std::vector<std::vector<vmap::VisualMap>> exhaustive_maps(seeds), fast_maps(seeds);
  std::vector<vmap::SweepResult> exhaustive_rows(seeds), fast_rows(seeds);
  for (int seed = 0; seed < seeds; ++seed) {
    auto a = vmap::OpenFrameSource(input);
    exhaustive_rows[seed] = vmap::SweepThresholds(*a, *matcher, Options(true, seed), taus, &exhaustive_maps[seed]);
    auto b = vmap::OpenFrameSource(input);
    fast_rows[seed] = vmap::SweepThresholds(*b, *matcher, Options(false, seed), taus, &fast_maps[seed]);
  }
  std::printf("\nm and Q per tau: exhaustive (OpenCV USAC_MAGSAC, seeds 0..%d) | default (seeds 0..%d)\n", seeds - 1,
              seeds - 1);
  std::printf("| tau | m, exhaustive | m, default | Q, exhaustive | Q, default |\n|---|---|---|---|---|\n");
  for (size_t t = 0; t < taus.size(); ++t) {
    std::string m_ex, m_fast, q_ex, q_fast;
    for (int seed = 0; seed < seeds; ++seed) {
      const char* sep = seed ? " " : "";
      m_ex += sep + std::to_string(exhaustive_rows[seed].rows[t].num_key_images);
      m_fast += sep + std::to_string(fast_rows[seed].rows[t].num_key_images);
      char buffer[32];
      std::snprintf(buffer, sizeof(buffer), "%s%.3f", sep, exhaustive_rows[seed].rows[t].quality);
      q_ex += buffer;
      std::snprintf(buffer, sizeof(buffer), "%s%.3f", sep, fast_rows[seed].rows[t].quality);
      q_fast += buffer;
    }
    std::printf("| %.1f | %s | %s | %s | %s |\n", taus[t], m_ex.c_str(), m_fast.c_str(), q_ex.c_str(), q_fast.c_str());
  }

  // Part 3: decisions of the exhaustive seed-0 sweep, made again.
  std::vector<std::shared_ptr<const vmap::ImageFeatures>> features;
  {
    auto source = vmap::OpenFrameSource(input);
    while (auto frame = source->Next()) features.push_back(matcher->Extract(frame->gray));
  }
  std::map<std::pair<int, int>, std::vector<double>> asked;  // pair -> taus whose maps compared it
  for (size_t t = 0; t < taus.size(); ++t) {
    for (const vmap::Evaluation& e : exhaustive_maps[0][t].evaluations)
      asked[{e.key_frame, e.frame}].push_back(taus[t]);
  }
  vmap::VerifierOptions other_seed;
  other_seed.seed = 1;
  vmap::VerifierOptions early;
  early.own_magsac = true;
  std::map<std::pair<int, int>, vmap::PairComparison> seed_one, fast;
  for (const auto& [pair, pair_taus] : asked) {
    const vmap::ImageFeatures& key = *features[pair.first];
    const vmap::ImageFeatures& frame = *features[pair.second];
    seed_one[pair] = vmap::ComparePair(*matcher, key, frame, other_seed, vmap::SimilarityMode::kInlierRatio);
    fast[pair] = vmap::ComparePair(*matcher, key, frame, early, vmap::SimilarityMode::kInlierRatio, pair_taus);
  }
  std::printf("\ndecisions S >= tau of the exhaustive sweep (seed 0) flipped when the same pairs are compared again\n");
  std::printf("| tau | decisions | OpenCV, seed 1 | vmap, early stop |\n|---|---|---|---|\n");
  int total = 0, total_seed = 0, total_fast = 0;
  for (size_t t = 0; t < taus.size(); ++t) {
    int decisions = 0, flipped_seed = 0, flipped_fast = 0;
    for (const vmap::Evaluation& e : exhaustive_maps[0][t].evaluations) {
      const bool reference = e.matched && e.similarity >= taus[t];
      const auto pair = std::make_pair(e.key_frame, e.frame);
      ++decisions;
      flipped_seed += seed_one[pair].Reaches(taus[t]) != reference;
      flipped_fast += fast[pair].Reaches(taus[t]) != reference;
    }
    std::printf("| %.1f | %d | %d | %d |\n", taus[t], decisions, flipped_seed, flipped_fast);
    total += decisions;
    total_seed += flipped_seed;
    total_fast += flipped_fast;
  }
  std::printf("| all | %d | %d | %d |\n", total, total_seed, total_fast);
  return 0;
}
