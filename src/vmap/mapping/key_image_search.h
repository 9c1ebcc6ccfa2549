#pragma once
// The bisect search for key images (MapBuilderOptions::key_search kBisect), a batch build of its own.

#include <filesystem>
#include <string>

#include "vmap/features/matcher.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/map_builder_options.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// Algorithm 1 with a search for the first frame below tau instead of a frame-by-frame scan. From the key image
// and the last frame known to pass against it, frames ever further ahead are compared (offsets doubling, at
// most search_window ahead), then the first failing frame is found by bisection. The last passing frame and the
// first failing one are then given to a KeyImageSelector, which, from the cached comparisons, makes the key
// images, links and links below tau Algorithm 1 makes on the whole sequence wherever S decreases with the
// distance to the key image. Each round compares one frame per thread at once; a frame's features are extracted
// only when it is compared, and only the frames the search may still compare are held.
VisualMap SearchKeyImages(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                          const std::filesystem::path& directory, const std::string& options_json);

}  // namespace vmap
