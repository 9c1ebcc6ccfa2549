#pragma once
// Reading and writing map directories.
//
// A map directory holds:
//   map.json             versioned description: input, options, n, m, Q, key images, links, evaluations
//   keys/NNNNNN.png      the key images (NNNNNN = frame index in the processed sequence; .jpg etc. when the
//                        key image is a copy of the input image file)
//   correspondences.bin  every link's tentative matches, little-endian float32 records (x0, y0, x1, y1),
//                        pixel coordinates with pixel centres at integers (OpenCV); each link names its
//                        `offset` (first record) and `count`; its first `verified` records are the inliers.

#include <filesystem>
#include <string>

#include "vmap/mapping/visual_map.h"

namespace vmap {

inline constexpr int kMapSchemaVersion = 1;
inline constexpr const char* kMapFileName = "map.json";
inline constexpr const char* kCorrespondencesFileName = "correspondences.bin";

// Writes map.json and correspondences.bin into `directory` (which must exist; key images are written by
// the builder). Each file is written atomically.
void WriteMapFiles(const VisualMap& map, const std::filesystem::path& directory);

// Reads a map directory. Throws InputError naming the file and what is wrong when it is missing or
// malformed, including key-image paths that would point outside the directory.
VisualMap ReadMap(const std::filesystem::path& directory);

// The map.json document alone (for tools that want the raw JSON).
std::string MapToJson(const VisualMap& map);

}  // namespace vmap
