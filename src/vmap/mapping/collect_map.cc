#include "vmap/mapping/collect_map.h"

#include <chrono>
#include <optional>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/stopwatch.h"
#include "vmap/features/camera_mask.h"

namespace vmap {

VisualMap CollectMap(const KeyImageSelector& selector, const FrameSource& source, const Matcher& matcher,
                     const MapBuilderOptions& options, const std::string& options_json, double seconds,
                     bool analyze_links, const LinkVerifier* link_verifier, double tau,
                     LinkAnalysisCache* analysis_cache, MapWriter* key_image_files,
                     const std::function<void()>& link_done) {
  VisualMap map;
  map.input = source.info();
  map.input.absolute_path = AbsoluteInputPath(map.input.path);
  if (const CameraMask* mask = CameraMaskOf(matcher); mask && !map.input.frame_size.empty()) {
    map.camera_mask = mask->For(map.input.frame_size);
  }
  map.options_json = options_json;
  map.num_frames = selector.num_frames();
  map.skipped_frames = source.skipped_frames();
  map.key_images = selector.key_images();
  map.links = selector.links();
  map.evaluations = selector.evaluations();
  map.seconds = seconds;
  if (link_verifier) {
    const int kept = link_verifier->Apply(&map, tau);
    if (kept > 0) {
      spdlog::debug("tau {:.2f}: {} of {} links kept the deciding estimate (the full one crossed tau)", tau, kept,
                    map.links.size());
    }
  }
  map.quality = ComputeStatistics(map, options.quality_mean).quality;
  if (!analyze_links) return map;
  const auto analysis_start = std::chrono::steady_clock::now();
  const long reused_before = analysis_cache ? analysis_cache->hits() : 0;
  std::optional<PoseCheckInputs> pose_check;
  if (key_image_files) {
    key_image_files->FlushKeyImages();
    pose_check = PoseCheckInputs{[directory = key_image_files->directory()](const KeyImage& key) {
                                   return ReadKeyImage(directory, key, /*grayscale=*/true);
                                 },
                                 options.verifier};
  }
  AnalyzeLinks(map, options.link_analysis, options.ExtractionThreads(), analysis_cache,
               pose_check ? &*pose_check : nullptr, link_done);
  const double analysis_seconds = SecondsSince(analysis_start);
  spdlog::debug("pose, parallax and homography test of {} links in {:.3f} s ({} analysed before)", map.links.size(),
                analysis_seconds, analysis_cache ? analysis_cache->hits() - reused_before : 0);
  map.seconds += analysis_seconds;  // part of building the map
  return map;
}

void ThrowNoFrameUsed(const FrameSource& source) {
  const int skipped = source.skipped_frames();
  throw InputError(fmt::format(
      "no frame of '{}' could be used{}: there is no map to write; check the input and --first, --last, --topic",
      source.info().path, skipped > 0 ? fmt::format(" ({} skipped, see the warnings above)", skipped) : ""));
}

}  // namespace vmap
