#pragma once
// A selector's map as it stands: key images, links (verified in full where the decisions stopped early),
// evaluations, quality and, when asked, each link's analysis (internal to mapping/).

#include <functional>
#include <string>

#include "vmap/features/matcher.h"
#include "vmap/map/map_writer.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/mapping/link_analysis.h"
#include "vmap/mapping/link_verifier.h"
#include "vmap/mapping/map_builder_options.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// `link_verifier` (when the decisions stopped early): the links verified in full replace the deciding ones.
// `analyze_links`: also each link's pose, parallax and homography test (only maps that are kept need them),
// reusing those of `analysis_cache` where the links did not change. `key_image_files`: the writer the key images
// went to, from which the links' cross-check (LinkAnalysisOptions::pose_check_features) reads them back.
// The map keeps the camera mask `matcher` extracted within (CameraMaskOf), at the frames' size. `link_done`: called
// as each link's analysis is done (AnalyzeLinks).
VisualMap CollectMap(const KeyImageSelector& selector, const FrameSource& source, const Matcher& matcher,
                     const MapBuilderOptions& options, const std::string& options_json, double seconds,
                     bool analyze_links, const LinkVerifier* link_verifier = nullptr, double tau = 0.0,
                     LinkAnalysisCache* analysis_cache = nullptr, MapWriter* key_image_files = nullptr,
                     const std::function<void()>& link_done = {});

// Throws the InputError of a build that took no frame of `source` (none could be used, or none was there):
// a map without a key image is no map, and no command would read it.
[[noreturn]] void ThrowNoFrameUsed(const FrameSource& source);

}  // namespace vmap
