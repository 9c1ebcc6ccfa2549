#include "vmap/mapping/batch_build.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "vmap/core/error.h"
#include "vmap/core/stopwatch.h"
#include "vmap/map/map_writer.h"
#include "vmap/mapping/key_image_search.h"
#include "vmap/mapping/map_builder.h"
#include "vmap/sources/read_ahead_source.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// Runs one selector per tau over one pass of the source; directories[i] receives tau i's map (no directory:
// the map stays in memory only). Maps returned whole, their evaluations read back from the writers.
SweepResult RunSelectors(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                         const std::vector<double>& taus, const std::vector<fs::path>& directories,
                         std::vector<VisualMap>* maps, const std::string& options_json) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<MapWriter>> writers;
  std::vector<MapWriter*> sinks;
  for (const fs::path& directory : directories) {
    writers.push_back(directory.empty() ? nullptr : std::make_unique<MapWriter>(directory));
    sinks.push_back(writers.back().get());
  }
  // Maps are only written when they are kept (vmap sweep --keep-maps, BuildMap): their links need analysing.
  const bool analyze_links = maps != nullptr;
  // Decoding on a thread of its own overlaps with Algorithm 1 on this one (measured: without it, lab_floor's
  // build took longer, side by side).
  ReadAheadSource frames(source, options.prefetch_frames);
  MapBuilder builder(frames, matcher, options, taus, sinks, options_json);
  while (std::optional<Frame> frame = frames.Next()) {
    builder.Add(std::move(*frame));
    if (options.after_frame) options.after_frame();
  }
  std::vector<VisualMap> built = builder.FinishAll(CoverageEnd::kInputEnded, analyze_links, /*with_evaluations=*/true);

  SweepResult result;
  // The sweep's own time: its maps' links are analysed one after another, so no map's seconds is the sweep's.
  result.seconds = SecondsSince(start);
  result.options_json = options_json;
  result.input = frames.info();
  result.input.absolute_path = AbsoluteInputPath(result.input.path);
  result.features_extracted = builder.features_extracted();
  result.pairs_matched = builder.pairs_matched();
  result.links_verified = builder.links_verified();
  for (size_t i = 0; i < built.size(); ++i) {
    VisualMap& map = built[i];
    const MapStatistics stats = ComputeStatistics(map, options.quality_mean);
    result.num_frames = map.num_frames;
    SweepRow row;
    row.tau = taus[i];
    row.num_key_images = stats.num_key_images;
    row.key_image_percent = stats.num_frames > 0 ? 100.0 * stats.num_key_images / stats.num_frames : 0.0;
    row.min_verified = stats.min_verified;
    row.max_verified = stats.max_verified;
    row.mean_verified = stats.mean_verified;
    row.mean_similarity = stats.mean_similarity;
    row.quality = stats.quality;
    row.below_tau_links = stats.below_tau_links;
    row.map_directory = directories[i].string();
    result.rows.push_back(row);
    if (result.best_row < 0 || row.quality > result.rows[result.best_row].quality) {
      result.best_row = static_cast<int>(i);
    }
    if (maps) maps->push_back(std::move(map));
  }
  return result;
}

}  // namespace

VisualMap BuildMap(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                   const fs::path& directory, const std::string& options_json) {
  if (ResolveKeySearch(options) == KeySearch::kBisect) {
    return SearchKeyImages(source, matcher, options, directory, options_json);
  }
  std::vector<VisualMap> maps;
  RunSelectors(source, matcher, options, {options.key_images.tau}, {directory}, &maps, options_json);
  return std::move(maps.front());
}

SweepResult SweepThresholds(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::vector<double>& taus, std::vector<VisualMap>* maps,
                            const fs::path& maps_directory, const std::string& options_json) {
  if (options.key_search == KeySearch::kBisect) {
    throw OptionError("key_search",
                      "bisect looks for each tau's key images on its own; a sweep compares every frame once for all "
                      "taus. Build one map per tau with key_search bisect instead",
                      {"key_search"});
  }
  std::vector<fs::path> directories;
  for (double tau : taus) {
    directories.push_back(maps_directory.empty() ? fs::path() : maps_directory / fmt::format("tau_{:.2f}", tau));
    if (std::count(directories.begin(), directories.end(), directories.back()) > 1 && !maps_directory.empty()) {
      throw InputError(
          fmt::format("two thresholds round to the same map folder '{}'; the maps are named with two "
                      "decimals, so give thresholds at least 0.01 apart",
                      directories.back().filename().string()));
    }
  }
  for (const fs::path& directory : directories) {
    if (!directory.empty()) fs::create_directory(directory);  // inside maps_directory, which must exist
  }
  return RunSelectors(source, matcher, options, taus, directories, maps, options_json);
}

}  // namespace vmap
