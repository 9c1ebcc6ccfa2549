#pragma once

#include <utility>

#include "vmap/map/visual_map.h"

namespace vmap {

// The key images on either side of position `source_index` of the map's input (KeyImage::source_index):
// the last key image at or before it and the first at or after it; -1 where there is none. A frame of the
// teach run's path between two key images is rightly localized at either (the bracket test of
// docs/measurements/localization.md).
std::pair<int, int> KeysAround(const VisualMap& map, int source_index);

}  // namespace vmap
