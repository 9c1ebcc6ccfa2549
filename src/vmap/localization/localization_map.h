#pragma once
// A map opened for localization: the map, the matcher it was built with (rebuilt from map.json), and its
// key images' features (cached; see key_image_store.h).

#include <filesystem>
#include <memory>
#include <string>

#include "vmap/features/matcher.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/localization/key_image_store.h"
#include "vmap/localization/localizer.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap {

struct LocalizationMap {
  std::filesystem::path directory;
  VisualMap map;
  RecordedOptions options;              // what the map records of the options that shaped it
  std::unique_ptr<Matcher> matcher;     // the map's matcher, with the map's options
  std::vector<Experience> experiences;  // map/experiences.h; their views' features are in `keys`
  KeyImageStore keys;
};

// Reads the map with its experiences and its options (ReadRecordedMap), creates its matcher
// (MatcherOptionsFromJson) and loads its key images and views.
// Throws InputError naming the file and the fix when any of it fails.
LocalizationMap OpenLocalizationMap(const std::filesystem::path& directory, const KeyImageStoreOptions& options,
                                    const MatcherRunSettings& matcher_run = {});
// The same for a map already read from `directory` (ReadRecordedMap): a map is read once. `matcher`: the map's
// (CreateMapMatcher), created before so that the caller could open its frames as the matcher reads them.
LocalizationMap OpenLocalizationMap(RecordedMap read, const std::filesystem::path& directory,
                                    const KeyImageStoreOptions& options, std::unique_ptr<Matcher> matcher);
// The matcher a map was built with, from its record (MatcherOptionsFromJson), within the map's camera mask (the
// robot's camera is the teach run's), computing where `run` says and reading the weights it names (weights of
// another model than the map's are refused, naming the file).
std::unique_ptr<Matcher> CreateMapMatcher(const RecordedMap& read, const std::filesystem::path& directory,
                                          const MatcherRunSettings& run = {});

// Localizer options that follow the map: its verifier (iterations capped, see MapVerifierOptions) and its
// definition of S; the rest are LocalizerOptions' defaults.
LocalizerOptions MapLocalizerOptions(const LocalizationMap& opened);

// The size frames are localized at: `resize` when given, otherwise the map's frame size as "WxH" (key images
// and frames are compared at one size; "" for a map that records none).
std::string QueryResize(const VisualMap& map, const std::string& resize);

// `options` made to follow the map (MapLocalizerOptions): its verifier (seeded with `options.verifier_seed` when
// that is not -1) and definition of S, and its camera when the frames are localized at the map's frame size
// (`query_resize`, QueryResize's), since the camera describes frames of that size; otherwise headings stay in pixels,
// without relative poses (a warning says so).
LocalizerOptions FollowMap(const LocalizationMap& opened, LocalizerOptions options, const std::string& query_resize);

}  // namespace vmap
