#include "vmap/localization/localization_map.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/features/camera_mask.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap {

LocalizationMap OpenLocalizationMap(const std::filesystem::path& directory, const KeyImageStoreOptions& options) {
  return OpenLocalizationMap(ReadRecordedMap(directory), directory, options);
}

LocalizationMap OpenLocalizationMap(RecordedMap read, const std::filesystem::path& directory,
                                    const KeyImageStoreOptions& options) {
  LocalizationMap opened;
  opened.directory = directory;
  opened.map = std::move(read.map);
  opened.options = std::move(read.options);
  opened.matcher =
      CreateMatcher(MatcherOptionsFromJson(opened.options.matcher_json, (directory / kMapFileName).string()));
  // The frames are extracted within the mask the key images were (the robot's camera is the teach run's).
  if (!opened.map.camera_mask.empty()) {
    opened.matcher = WithCameraMask(
        std::move(opened.matcher), CameraMask(opened.map.camera_mask, "the map's " + std::string(kCameraMaskFileName)));
  }
  opened.experiences = opened.map.experiences;
  opened.keys = LoadKeyImageStore(directory, opened.map, *opened.matcher, options, opened.experiences);
  return opened;
}

LocalizerOptions MapLocalizerOptions(const LocalizationMap& opened) {
  const MapBuilderOptions& recorded = opened.options.builder;
  LocalizerOptions options;
  options.verifier = MapVerifierOptions(recorded.verifier);
  options.similarity = recorded.key_images.similarity;
  options.camera = opened.map.input.camera;
  options.translation = recorded.link_analysis.translation;
  options.map_tau = recorded.key_images.tau;
  return options;
}

std::string QueryResize(const VisualMap& map, const std::string& resize) {
  if (!resize.empty() || map.input.frame_size.empty()) return resize;
  return fmt::format("{}x{}", map.input.frame_size.width, map.input.frame_size.height);
}

LocalizerOptions FollowMap(const LocalizationMap& opened, LocalizerOptions options, const std::string& query_resize) {
  const VisualMap& map = opened.map;
  const LocalizerOptions from_map = MapLocalizerOptions(opened);
  options.verifier = from_map.verifier;
  if (options.verifier_seed >= 0) options.verifier.seed = options.verifier_seed;
  options.similarity = from_map.similarity;
  options.translation = from_map.translation;
  options.map_tau = from_map.map_tau;
  if (options.link_share_tau == 0.0) options.link_share_tau = DefaultTau(opened.matcher->name());
  const std::string map_size = QueryResize(map, "");
  if (from_map.camera && !map_size.empty() && query_resize == map_size) {
    options.camera = from_map.camera;
  } else if (from_map.camera) {
    spdlog::warn("--resize {} differs from the map's frame size {}: headings in pixels only, no relative poses",
                 query_resize, map_size);
  }
  return options;
}

}  // namespace vmap
