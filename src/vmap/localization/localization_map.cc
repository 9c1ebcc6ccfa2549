#include "vmap/localization/localization_map.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/features/matcher_registry.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap {

LocalizationMap OpenLocalizationMap(const std::filesystem::path& directory, const KeyImageStoreOptions& options) {
  LocalizationMap opened;
  opened.directory = directory;
  opened.map = ReadMap(directory);
  const std::string map_file = (directory / kMapFileName).string();
  const RecordedOptions recorded = RecordedOptionsFromJson(opened.map.options_json, "map '" + map_file + "': options");
  opened.matcher = CreateMatcher(MatcherOptionsFromJson(recorded.matcher_json, map_file));
  opened.experiences = ReadExperiences(directory, opened.map);
  opened.keys = LoadKeyImageStore(directory, opened.map, *opened.matcher, options, opened.experiences);
  return opened;
}

LocalizerOptions MapLocalizerOptions(const VisualMap& map) {
  LocalizerOptions options;
  options.verifier = MapVerifierOptions(map);
  options.similarity = MapSimilarityMode(map);
  options.camera = map.input.camera;
  options.translation = MapTranslationOptions(map);
  return options;
}

std::string QueryResize(const VisualMap& map, const std::string& resize) {
  if (!resize.empty() || map.input.frame_size.empty()) return resize;
  return fmt::format("{}x{}", map.input.frame_size.width, map.input.frame_size.height);
}

LocalizerOptions FollowMap(const VisualMap& map, LocalizerOptions options, const std::string& query_resize) {
  const LocalizerOptions from_map = MapLocalizerOptions(map);
  options.verifier = from_map.verifier;
  options.similarity = from_map.similarity;
  options.translation = from_map.translation;
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
