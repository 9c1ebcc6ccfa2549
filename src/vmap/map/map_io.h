#pragma once
// Reading and writing map directories.
//
// A map directory holds:
//   map.json             versioned description: input, options, n, m, Q, key images, links, evaluations;
//                        file names and paths percent-encoded where they are not UTF-8 (file_name_encoding.h)
//   keys/NNNNNN.png      the key images (NNNNNN = frame index in the processed sequence; .jpg etc. when the
//                        key image is a copy of the input image file)
//   correspondences.bin  every link's tentative matches, little-endian float32 records (x0, y0, x1, y1),
//                        pixel coordinates with pixel centres at integers (OpenCV); each link names its
//                        `offset` (first record) and `count`; its first `verified` records are the inliers.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>

#include "vmap/map/visual_map.h"

namespace vmap {

// 2: links say `below_tau` (version 1: `broken`) and carry their pose, parallax and homography test; the
// input may have a camera. Version 1 maps are still read.
inline constexpr int kMapSchemaVersion = 2;
inline constexpr const char* kMapFileName = "map.json";
inline constexpr const char* kCorrespondencesFileName = "correspondences.bin";
// The map's camera mask (VisualMap::camera_mask), when it has one: an 8-bit grey PNG, black where no features may be.
inline constexpr const char* kCameraMaskFileName = "camera_mask.png";
// Limits a map must respect to be read, far above what vmap writes: they bound the memory a crafted map
// can make a reader take.
inline constexpr std::uint64_t kMaxMapJsonBytes = 1ull << 30;  // 1 GiB
inline constexpr long kMaxMatchesPerLink = 1L << 22;           // 4,194,304 correspondences
// Values (numbers, strings, arrays, objects) in map.json: 8.4 million, far above a map of 100,000 key images
// whose 400,000 frames were each compared three times (some 6 values a comparison); parsed, this many take
// at most some hundred MB, where 150 million numbers would take gigabytes.
inline constexpr std::uint64_t kMaxMapJsonValues = 1ull << 23;

// Writes map.json and correspondences.bin into `directory` (which must exist; key images are written by
// the builder). Each file is written atomically.
void WriteMapFiles(const VisualMap& map, const std::filesystem::path& directory);
// Writes kCameraMaskFileName into `directory` when the map has a camera mask (before map.json, which names it).
void WriteCameraMask(const VisualMap& map, const std::filesystem::path& directory);

// Calls its argument with each evaluation of a map, in order; may be called several times (once per column
// of map.json). A map being built keeps its evaluations in a file (MapWriter) and reads them back this way.
using EvaluationSource = std::function<void(const std::function<void(const Evaluation&)>&)>;

// map.json as WriteMapFiles writes it, streamed to `out`, with the evaluations from `evaluations` instead of
// map.evaluations when given: memory does not grow with their number.
void WriteMapJson(std::ostream& out, const VisualMap& map, const EvaluationSource& evaluations = nullptr);

// correspondences.bin's content for `map`'s links.
std::string CorrespondencesBinary(const VisualMap& map);

// "input ended", "interrupted", "snapshot" (map.json's coverage.end).
std::string CoverageEndName(CoverageEnd end);

// The width and height a key-image file's header announces (PNG, or JPEG: a key image copied from the input's
// own file, which may be a link), as ReadMap checks them; nullopt when the file is neither, is not a regular file or
// cannot be read.
std::optional<cv::Size> KeyImageFileSize(const std::filesystem::path& file);

// The file of key image `key` of the map in `map_directory`, checked again as ReadMap checks it (inside the map
// directory, a regular file): a map read earlier may have changed on disk since. Throws InputError naming the
// file and the fix.
std::filesystem::path KeyImageFile(const std::filesystem::path& map_directory, const KeyImage& key);

// Decodes key image `key` (in colour, or grey straight from the decoder as the image sources read frames).
// Throws InputError naming the file when it is gone, leads outside the map, cannot be decoded, or its header
// announces another size than `frame_size` (the map's input.frame_size; when empty, more pixels than a frame).
cv::Mat ReadKeyImage(const std::filesystem::path& map_directory, const KeyImage& key, bool grayscale = false,
                     const cv::Size& frame_size = {});

// Reads a map directory that vmap may not have written (a map someone sent). Throws InputError naming the file,
// the field and what is wrong when it is missing or malformed. It never reads outside the directory (no
// absolute or ".." paths, no symbolic link leading out, only regular files), checks every file's size against
// map.json before reading it (correspondences.bin must be exactly as long as its links say; each key image a
// PNG or JPEG of the map's frame size), reads only the byte ranges the links reference, and checks every field's type
// and range (F: null or 9 finite numbers; counts and offsets that fit; key-image and frame indices in range).
// File names and paths are decoded (DecodeFileName).
VisualMap ReadMap(const std::filesystem::path& directory);

// The proof that `directory` is a map vmap wrote, so that `vmap build -o` may replace it: "" when its map.json
// is a vmap map ("format": "vmap-map" and an integer "schema_version"), otherwise why it is not.
std::string WhyNotAVmapMap(const std::filesystem::path& directory);

// The map.json document alone (for tools that want the raw JSON).
std::string MapToJson(const VisualMap& map);

}  // namespace vmap
