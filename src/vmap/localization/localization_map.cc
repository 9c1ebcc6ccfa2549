#include "vmap/localization/localization_map.h"

#include <nlohmann/json.hpp>

#include "vmap/features/matcher_registry.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/map/map_io.h"

namespace vmap {

LocalizationMap OpenLocalizationMap(const std::filesystem::path& directory, const KeyImageStoreOptions& options) {
  LocalizationMap opened;
  opened.directory = directory;
  opened.map = ReadMap(directory);
  const std::string map_file = (directory / kMapFileName).string();
  const auto doc = nlohmann::json::parse(opened.map.options_json, nullptr, false);
  const std::string matcher_json =
      doc.is_object() && doc.contains("matcher") ? doc["matcher"].dump() : std::string("{}");
  opened.matcher = CreateMatcher(MatcherOptionsFromJson(matcher_json, map_file));
  opened.keys = LoadKeyImageStore(directory, opened.map, *opened.matcher, options);
  return opened;
}

LocalizerOptions MapLocalizerOptions(const VisualMap& map) {
  LocalizerOptions options;
  options.verifier = MapVerifierOptions(map);
  options.similarity = MapSimilarityMode(map);
  options.camera = map.input.camera;
  return options;
}

}  // namespace vmap
