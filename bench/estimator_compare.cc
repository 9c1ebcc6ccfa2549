// vmap's MAGSAC++ (geometry/magsac.h) against OpenCV's USAC_MAGSAC on real pairs: ORB tentative matches between
// frames i and i + d of the sequences in ../shared/data, d spread so that S covers (0, 1).
//
//   estimator_compare [--seeds K] [--frames N] [--pairs-per-gap P] [SEQUENCE ...]
//
// For each pair, both estimators run with seeds 0..K-1 (exhaustive), and vmap's also with early stopping for
// tau = 0.1..0.9 at once (as a sweep asks) and for tau = 0.5 alone (as a build asks). Printed:
//  * S: mean |S_vmap(seed s) - S_opencv(seed s)| against mean |S_opencv(seed s) - S_opencv(seed 0)|, s > 0, and the
//    mean signed difference of the seed-averaged S;
//  * decisions S >= tau flipped against OpenCV seed 0, per tau: by OpenCV with another seed, by vmap exhaustive,
//    by vmap stopping early;
//  * CPU time and iterations of each.
// Everything runs on one thread, one estimator after the other, pair by pair.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/runtime.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/magsac.h"
#include "vmap/sources/frame_source.h"

namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

const std::vector<double> kTaus = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9};

struct PairResult {
  int n = 0;
  std::vector<double> opencv, own;  // S per seed (0 when no model)
  double own_early_sweep = 0, own_early_build = 0;
};

double Similarity(const vmap::FundamentalResult& r, int n) { return r.success ? double(r.num_inliers) / n : 0.0; }

}  // namespace

int main(int argc, char** argv) {
  int seeds = 3, frames_per_sequence = 120, pairs_per_gap = 6;
  bool verbose = false;
  std::vector<std::string> sequences;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seeds") && i + 1 < argc)
      seeds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
      frames_per_sequence = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--pairs-per-gap") && i + 1 < argc)
      pairs_per_gap = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--verbose"))
      verbose = true;
    else
      sequences.push_back(argv[i]);
  }
  if (sequences.empty()) {
    const std::string shared = VMAP_SHARED_DIR;
    sequences = {shared + "/data/rccar_room/images", shared + "/data/lab_floor/lab_floor.mp4", shared + "/data/kitti07",
                 shared + "/data/redkitchen"};
  }
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  const auto matcher = vmap::CreateOrbMatcher({});
  const std::vector<int> gaps = {1, 2, 3, 5, 8, 13, 21, 34, 55};

  std::vector<PairResult> results;
  double time_opencv = 0, time_own = 0, time_early_sweep = 0, time_early_build = 0;
  long iterations_own = 0, iterations_sweep = 0, iterations_build = 0;
  for (const std::string& path : sequences) {
    vmap::FrameSourceOptions source_options;
    source_options.last = frames_per_sequence - 1;
    auto source = vmap::OpenFrameSource(path, source_options);
    std::vector<std::shared_ptr<const vmap::ImageFeatures>> features;
    while (auto frame = source->Next()) features.push_back(matcher->Extract(frame->gray));
    const int count = static_cast<int>(features.size());
    int pairs = 0;
    for (int gap : gaps) {
      for (int k = 0; k < pairs_per_gap; ++k) {
        const int i = static_cast<int>((count - gap - 1) * (k + 0.5) / pairs_per_gap);
        if (i < 0 || i + gap >= count) continue;
        const vmap::TentativeMatches matches = matcher->Match(*features[i], *features[i + gap]);
        PairResult pair;
        pair.n = static_cast<int>(matches.size());
        if (pair.n < 8) continue;
        for (int seed = 0; seed < seeds; ++seed) {
          vmap::VerifierOptions options;
          options.seed = seed;
          auto start = Clock::now();
          pair.opencv.push_back(
              Similarity(vmap::EstimateFundamental(matches.points0, matches.points1, options), pair.n));
          time_opencv += Seconds(start);
          start = Clock::now();
          vmap::MagsacStatistics stats;
          pair.own.push_back(Similarity(
              vmap::EstimateFundamentalMagsac(matches.points0, matches.points1, options, {}, &stats), pair.n));
          time_own += Seconds(start);
          iterations_own += stats.iterations;
        }
        vmap::VerifierOptions options;
        vmap::EarlyStop sweep, build;
        for (double tau : kTaus)
          sweep.min_inliers.push_back(std::max(8, static_cast<int>(std::ceil(tau * pair.n - 1e-9))));
        build.min_inliers.push_back(std::max(8, static_cast<int>(std::ceil(0.5 * pair.n - 1e-9))));
        vmap::MagsacStatistics stats;
        auto start = Clock::now();
        pair.own_early_sweep = Similarity(
            vmap::EstimateFundamentalMagsac(matches.points0, matches.points1, options, sweep, &stats), pair.n);
        time_early_sweep += Seconds(start);
        iterations_sweep += stats.iterations;
        start = Clock::now();
        pair.own_early_build = Similarity(
            vmap::EstimateFundamentalMagsac(matches.points0, matches.points1, options, build, &stats), pair.n);
        time_early_build += Seconds(start);
        iterations_build += stats.iterations;
        if (verbose) {
          std::printf("pair %d-%d n=%d opencv", i, i + gap, pair.n);
          for (double v : pair.opencv) std::printf(" %.3f", v);
          std::printf(" vmap");
          for (double v : pair.own) std::printf(" %.3f", v);
          std::printf(" early %.3f %.3f\n", pair.own_early_sweep, pair.own_early_build);
        }
        results.push_back(pair);
        ++pairs;
      }
    }
    std::printf("%s: %d frames, %d pairs\n", path.c_str(), count, pairs);
  }

  // S agreement.
  double seed_noise = 0, own_seed_noise = 0, own_vs_opencv = 0, signed_difference = 0;
  int seed_terms = 0, own_terms = 0;
  std::map<int, std::pair<double, int>> signed_by_bin;
  for (const PairResult& p : results) {
    for (int s = 1; s < seeds; ++s) seed_noise += std::abs(p.opencv[s] - p.opencv[0]), ++seed_terms;
    for (int s = 1; s < seeds; ++s) own_seed_noise += std::abs(p.own[s] - p.own[0]);
    for (int s = 0; s < seeds; ++s) own_vs_opencv += std::abs(p.own[s] - p.opencv[s]), ++own_terms;
    double mean_cv = 0, mean_own = 0;
    for (int s = 0; s < seeds; ++s) mean_cv += p.opencv[s] / seeds, mean_own += p.own[s] / seeds;
    signed_difference += mean_own - mean_cv;
    auto& bin = signed_by_bin[std::min(9, static_cast<int>(mean_cv * 10))];
    bin.first += mean_own - mean_cv;
    ++bin.second;
  }
  std::printf("\n%zu pairs, %d seeds\n", results.size(), seeds);
  std::printf("mean |S_opencv(seed s) - S_opencv(seed 0)|, s > 0: %.4f\n", seed_noise / std::max(1, seed_terms));
  std::printf("mean |S_vmap(seed s) - S_vmap(seed 0)|, s > 0:     %.4f\n", own_seed_noise / std::max(1, seed_terms));
  std::printf("mean |S_vmap(seed s) - S_opencv(seed s)|:          %.4f\n", own_vs_opencv / std::max(1, own_terms));
  std::printf("mean S_vmap - S_opencv (seed-averaged):            %+.4f\n", signed_difference / results.size());
  for (const auto& [bin, value] : signed_by_bin) {
    std::printf("  S_opencv in [%.1f, %.1f): %4d pairs, mean S_vmap - S_opencv %+.4f\n", bin / 10.0, (bin + 1) / 10.0,
                value.second, value.first / value.second);
  }

  // Decisions.
  std::printf("\ndecisions S >= tau flipped against OpenCV seed 0 (of %zu pairs)\n", results.size());
  std::printf(
      "| tau | OpenCV, seed 1 | vmap exhaustive, seed 0 | vmap exhaustive, seed 1 | vmap early stop (9 taus) |%s\n",
      " vmap early stop (tau alone, 0.5) |");
  int totals[5] = {0, 0, 0, 0, 0};
  for (double tau : kTaus) {
    int flips[5] = {0, 0, 0, 0, 0};
    for (const PairResult& p : results) {
      const bool reference = p.opencv[0] >= tau;
      if (seeds > 1 && (p.opencv[1] >= tau) != reference) ++flips[0];
      if ((p.own[0] >= tau) != reference) ++flips[1];
      if (seeds > 1 && (p.own[1] >= tau) != reference) ++flips[2];
      if ((p.own_early_sweep >= tau) != reference) ++flips[3];
      if (tau == 0.5 && (p.own_early_build >= tau) != reference) ++flips[4];
    }
    for (int k = 0; k < 5; ++k) totals[k] += flips[k];
    std::printf("| %.1f | %d | %d | %d | %d | %s |\n", tau, flips[0], flips[1], flips[2], flips[3],
                tau == 0.5 ? std::to_string(flips[4]).c_str() : "");
  }
  std::printf("| all | %d | %d | %d | %d | %d |\n", totals[0], totals[1], totals[2], totals[3], totals[4]);

  const double calls = static_cast<double>(results.size()) * seeds;
  std::printf("\nCPU per call (one thread): OpenCV USAC_MAGSAC %.3f ms, vmap exhaustive %.3f ms (%.0f iterations)\n",
              1e3 * time_opencv / calls, 1e3 * time_own / calls, iterations_own / calls);
  std::printf("vmap early stop, 9 taus: %.3f ms (%.0f iterations); tau 0.5 alone: %.3f ms (%.0f iterations)\n",
              1e3 * time_early_sweep / results.size(), double(iterations_sweep) / results.size(),
              1e3 * time_early_build / results.size(), double(iterations_build) / results.size());
  std::printf("OpenCV / vmap exhaustive: %.2fx; OpenCV / vmap early stop (9 taus): %.2fx; (tau 0.5): %.2fx\n",
              time_opencv / time_own, (time_opencv / seeds) / time_early_sweep,
              (time_opencv / seeds) / time_early_build);
  return 0;
}
