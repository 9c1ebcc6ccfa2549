#include "vmap/localization/localization_map.h"

#include "vmap/features/matcher_registry.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/map_builder.h"

namespace vmap {

LocalizationMap OpenLocalizationMap(const std::filesystem::path& directory, const KeyImageStoreOptions& options) {
  LocalizationMap opened;
  opened.directory = directory;
  opened.map = ReadMap(directory);
  const std::string map_file = (directory / kMapFileName).string();
  const RecordedOptions recorded = RecordedOptionsFromJson(opened.map.options_json, "map '" + map_file + "': options");
  opened.matcher = CreateMatcher(MatcherOptionsFromJson(recorded.matcher_json, map_file));
  opened.keys = LoadKeyImageStore(directory, opened.map, *opened.matcher, options);
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

}  // namespace vmap
