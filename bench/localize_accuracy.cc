// Localization measured against truth (docs/measurements/localization.md): the bracket test and the ranking recall.
//
//   localize_accuracy SEQUENCE [--last N] [--tau T] [--ranking auto|votes|thumbnails] [--candidates K]
//                     [--acceptance chance,counts] [--variants RULE/RECHECK/SHARE,...] [--orb-features N]
//
// Builds a map of the even frames of SEQUENCE (`vmap build --stride 2`, default options but --orb-features) in a
// temporary folder and localizes the odd frames against it:
//  - streaming (tracking, relocalizing when lost): the share of odd frames localized at one of the two key
//    images that bracket it in the input (KeysAround), and the status counts;
//  - every frame relocalized from scratch (Localizer::Reset before each): the same share, the time per
//    relocalization, and the recall of both rankings (a bracketing key image among the first 1 / K ranked);
//  - progress: where the estimate is the bracketing segment, the mean absolute difference between the
//    estimated progress and the frame's position between the two key images in input frames.
// With several acceptance rules (--acceptance, comma-separated; default: the localizer's defaults) or variants
// (--variants, bench/localizer_variants.h), the map is built once and each measurement runs once per variant, one
// after the other, so they compare side by side.
// Every figure comes from one run, so they compare; the machine's load changes the times.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "vmap/core/runtime.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/localization/key_image_ranking.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/map/map_io.h"

#include "bench_map.h"
#include "localizer_variants.h"

namespace fs = std::filesystem;
using namespace vmap;

namespace {

bool Brackets(const VisualMap& map, int source_index, int key) {
  const auto [before, after] = KeysAround(map, source_index);
  return key >= 0 && (key == before || key == after);
}

// The streaming and relocalization measurements with one set of localizer options.
void Measure(const std::string& input, const LocalizationMap& opened, const LocalizerOptions& options,
             const FrameSourceOptions& odd, int candidates, bool streaming_only) {
  const VisualMap& map = opened.map;
  // 1. Streaming.
  {
    Localizer localizer(map, opened.keys, *opened.matcher, options);
    auto source = OpenFrameSource(input, odd);
    long bracketed = 0, near = 0, progress_count = 0;
    double progress_error = 0.0;
    std::vector<std::string> misses;
    LocalizeSequenceOptions run_options;
    run_options.show_progress = false;
    const LocalizationSummary s = LocalizeSequence(
        *source, *opened.matcher, localizer, run_options, [&](const Frame& frame, const LocalizationResult& r) {
          const auto [low, high] = KeysAround(map, frame.source_index);
          if (r.key >= 0 && r.key >= low - 1 && (high < 0 || r.key <= high + 1)) ++near;
          if (Brackets(map, frame.source_index, r.key)) {
            ++bracketed;
          } else if (misses.size() < 12) {
            const auto [before, after] = KeysAround(map, frame.source_index);
            misses.push_back(std::to_string(frame.source_index) + ":" + LocalizationStatusName(r.status) + ":key " +
                             std::to_string(r.key) + " (bracket " + std::to_string(before) + "," +
                             std::to_string(after) + ")");
          }
          // Frames past the last key image (or before the first) have no segment: KeysAround gives -1 on that
          // side, which a result at the route's end matches (its next_key is -1 too).
          const auto [before, after] = KeysAround(map, frame.source_index);
          if (before >= 0 && after > before && r.key == before && r.next_key == after && std::isfinite(r.progress)) {
            const double a = map.key_images[before].source_index, b = map.key_images[after].source_index;
            progress_error += std::abs(r.progress - (frame.source_index - a) / (b - a));
            ++progress_count;
          }
        });
    std::printf(
        "streaming: %ld odd frames, bracketed %ld (%.1f%%), within one key image of the bracket %.1f%%; "
        "tracking %ld, relocalized %ld, lost %ld; %.1f frames/s, %.1f ms localizing per frame\n",
        s.frames, bracketed, 100.0 * bracketed / std::max(1L, s.frames), 100.0 * near / std::max(1L, s.frames),
        s.tracking, s.relocalized, s.lost, s.frames_per_second, 1000 * s.mean_localize_seconds);
    std::printf("progress: mean |estimate - truth| %.3f over %ld frames on their bracketing segment\n",
                progress_count ? progress_error / progress_count : 0.0, progress_count);
    for (const std::string& m : misses) std::printf("  miss %s\n", m.c_str());
  }

  // 2. Every frame relocalized from scratch, and both rankings' recall.
  if (!streaming_only) {
    Localizer localizer(map, opened.keys, *opened.matcher, options);
    LocalizerOptions thumb_options = options;
    KeyImageRanking votes(opened.keys.features, opened.keys.thumbnails, {});
    RankingOptions thumbnail_ranking;
    thumbnail_ranking.method = RankingMethod::kThumbnails;
    KeyImageRanking thumbnails(opened.keys.features, opened.keys.thumbnails, thumbnail_ranking);
    auto source = OpenFrameSource(input, odd);
    long frames = 0, bracketed = 0, localized = 0;
    long top1[2] = {0, 0}, topk[2] = {0, 0};
    double seconds = 0.0, worst = 0.0, rank_seconds[2] = {0.0, 0.0};
    while (auto frame = source->Next()) {
      const auto features = opened.matcher->Extract(frame->gray);
      localizer.Reset();
      const LocalizationResult r = localizer.Localize(*frame, *features);
      ++frames;
      localized += r.status != LocalizationStatus::kLost;
      bracketed += Brackets(map, frame->source_index, r.key);
      seconds += r.seconds;
      worst = std::max(worst, r.seconds);
      const cv::Mat thumbnail = ThumbnailDescriptor(frame->gray, thumb_options.ranking.thumbnail_width);
      const KeyImageRanking* rankings[2] = {&votes, &thumbnails};
      for (int m = 0; m < 2; ++m) {
        const auto start = std::chrono::steady_clock::now();
        const auto ranked = rankings[m]->Rank(*features, thumbnail);
        rank_seconds[m] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        for (int i = 0; i < std::min<int>(candidates, ranked.size()); ++i) {
          if (Brackets(map, frame->source_index, ranked[i].key)) {
            top1[m] += i == 0;
            ++topk[m];
            break;
          }
        }
      }
    }
    std::printf(
        "relocalization only: %ld frames, localized %ld, bracketed %ld (%.1f%%); %.1f ms per frame, "
        "worst %.1f ms\n",
        frames, localized, bracketed, 100.0 * bracketed / std::max(1L, frames), 1000 * seconds / frames, 1000 * worst);
    const char* names[2] = {"votes", "thumbnails"};
    for (int m = 0; m < 2; ++m) {
      std::printf("ranking %-10s: bracketing key first %.1f%%, among the first %d %.1f%%; %.2f ms per query\n",
                  names[m], 100.0 * top1[m] / frames, candidates, 100.0 * topk[m] / frames,
                  1000 * rank_seconds[m] / frames);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  // CLI11, as the vmap binary parses its flags: a flag it does not know, or one without its value, is an error
  // (a hand-written loop over pairs ignored a last `--streaming-only` and any misspelled flag).
  CLI::App app{
      "localize_accuracy: how many frames of a sequence the localizer brackets, against a map of its even frames"};
  std::string input;
  int last = -1, candidates = 5, lookahead = 2;
  bool step_back = true, streaming_only = false;
  double tau = 0.5;
  std::string ranking = "auto", acceptance, variant_list;
  MatcherOptions matcher_options;  // ORB with its defaults unless --orb-features
  app.add_option("sequence", input, "the sequence (a TUM RGB-D folder, an image folder or a video)")->required();
  app.add_option("--last", last, "the last frame read (-1: all)");
  app.add_option("--tau", tau, "the map's key image threshold");
  app.add_option("--ranking", ranking, "the key image ranking");
  app.add_option("--candidates", candidates, "relocalization candidates");
  app.add_option("--acceptance", acceptance, "acceptance variants to compare: chance,counts");
  app.add_option("--variants", variant_list, "localizer variants to compare: RULE/RECHECK/SHARE,...");
  app.add_option("--lookahead", lookahead, "the tracker's lookahead");
  app.add_flag("!--no-step-back", step_back, "never step back to the key image behind");
  app.add_flag("--streaming-only", streaming_only, "only the streaming pass (not the relocalization of every frame)");
  app.add_option("--orb-features", matcher_options.Of<OrbMatcherOptions>().num_features, "the map's ORB features");
  CLI11_PARSE(app, argc, argv);
  const std::vector<bench::LocalizerVariant> variants = bench::VariantsToCompare(acceptance, variant_list);
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  const fs::path map_directory = fs::temp_directory_path() / ("vmap_localize_accuracy_" + std::to_string(getpid()));

  // The map: even frames.
  MapBuilderOptions build_options;
  build_options.key_images.tau = tau;
  FrameSourceOptions even;
  even.stride = 2;
  even.last = last;
  LocalizationMap opened = bench::BuildAndOpenMap(input, even, matcher_options, build_options, map_directory);
  const VisualMap& map = opened.map;
  std::printf("%s: map of %d even frames, %zu key images (tau %.2f)\n", input.c_str(), map.num_frames,
              map.key_images.size(), tau);

  FrameSourceOptions odd = even;
  odd.first = 1;
  for (const bench::LocalizerVariant& variant : variants) {
    std::printf("--- %s\n", variant.Name().c_str());
    LocalizerOptions options = MapLocalizerOptions(opened);
    variant.ApplyTo(options);
    options.ranking.method = ParseRankingMethod(ranking);
    options.relocalization_candidates = candidates;
    options.lookahead = lookahead;
    options.step_back = step_back;
    Measure(input, opened, options, odd, candidates, streaming_only);
  }
  fs::remove_all(map_directory);
  return 0;
}
