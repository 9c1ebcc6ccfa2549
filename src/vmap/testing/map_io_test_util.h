#pragma once
// Test helpers of the map files' tests (map/map_io_test.cc, map/hostile_map_test.cc): a small map to write, and
// what ReadMap says of a map it refuses.

#include <filesystem>
#include <string>

#include "vmap/map/visual_map.h"

namespace vmap::testing {

// A map of 20 frames (64x48) with key images at frames 0, 9 and 19, each a PNG in `directory`/keys filled with its
// frame index, two links of three correspondences and two evaluations; its map files are not written.
VisualMap SmallMap(const std::filesystem::path& directory);

// Writes `text` into `file`.
void WriteText(const std::filesystem::path& file, const std::string& text);

// The message ReadMap refuses the map in `directory` with; "" when it reads the map.
std::string ReadMapError(const std::filesystem::path& directory);

}  // namespace vmap::testing
