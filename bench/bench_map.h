#pragma once
// The map a localization bench measures against (localize_accuracy, localize_repeat): some frames of a sequence
// built into a map as `vmap build` builds one (default options but those given), then opened as `vmap localize`
// opens it.

#include <filesystem>
#include <string>

#include "vmap/features/matcher_registry.h"
#include "vmap/localization/localization_map.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap::bench {

// Builds a map of `frames` of `input` with `matcher_options` and `build_options` (no progress shown) into
// `directory`, emptied or made first, and opens it. The caller removes `directory` when done.
inline LocalizationMap BuildAndOpenMap(const std::string& input, const FrameSourceOptions& frames,
                                       const MatcherOptions& matcher_options, MapBuilderOptions build_options,
                                       const std::filesystem::path& directory) {
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  const auto matcher = CreateMatcher(matcher_options);
  build_options.show_progress = false;
  {
    auto source = OpenFrameSource(input, frames);
    const VisualMap built =
        BuildMap(*source, *matcher, build_options, directory, DescribeMapOptions(*matcher, build_options, frames));
    WriteMapFiles(built, directory);
  }
  return OpenLocalizationMap(directory, {});
}

}  // namespace vmap::bench
