#pragma once
// The record of a localization run: CSV (one row per frame) and JSON (the run, a summary and every frame),
// and reading the JSON back (for `vmap report`).
//
// Per frame, in both: frame, source_index, timestamp, source_name, status, key, next_key, key_frame and
// next_key_frame (their frame indices in the map), similarity / verified / tentative against `key`,
// next_similarity / next_verified / next_tentative against `next_key`, heading_px, progress, comparisons,
// seconds, and F from the frame to the next key image (x_next^T F x_frame = 0; CSV columns F00..F22, JSON a
// row-major list; empty / null when there is none). With the map's camera also heading_deg and the pose of the
// target key image (next_key, or key at the route's end) relative to the frame, X_key = R X_frame + t with
// |t| = 1 (CSV R00..R22, tx, ty, tz; JSON "pose": {"R": row-major, "t"}). Then heading_confidence (of
// heading_px's estimate) and the heading against `key`: heading_key_px, heading_key_deg, heading_key_confidence
// (geometry/heading.h); translation_sigma_deg, translation_known and guidance; log10_nfa and next_log10_nfa,
// how unlikely the verified matches with `key` and `next_key` are by chance (KeyComparison::log10_nfa).
// Against a map with experiences (map/experiences.h), and only then, also experience and next_experience: the
// image of `key` and `next_key` the frame fitted best (0 the teach key image, n the view of experience n;
// KeyComparison::experience). Last, in both: confidence and key_rank (LocalizationResult). Unknown numbers are
// empty in CSV and null in JSON. New columns are only ever appended at the end.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/localizer.h"
#include "vmap/map/visual_map.h"

namespace vmap {

inline constexpr int kLocalizationSchemaVersion = 1;
// Limits a run's JSON must respect to be read (a few hundred bytes and some 40 values a frame): they bound the
// memory a crafted file can make `vmap report` take.
inline constexpr std::uint64_t kMaxRunJsonBytes = 1ull << 30;
inline constexpr std::uint64_t kMaxRunJsonValues = 1ull << 24;

// What a run was: the inputs and settings, recorded in the JSON.
struct LocalizationRunInfo {
  std::string map_directory;
  std::string query;  // the query's path as given
  // The two as absolute paths where the run was made: a run read back elsewhere (`vmap report RUN.json` from another
  // folder) finds them by these. Written from the two above; read back empty from a run that has none.
  std::string map_absolute_directory, query_absolute_path;
  SourceFormat query_format = SourceFormat::kAuto;
  FrameSourceOptions source;        // first, last, stride, resize
  cv::Size frame_size;              // of the query frames as localized
  std::string matcher;              // the map's matcher
  std::string ranking;              // the ranking in use
  std::string cache;                // KeyImageCacheStateName
  double key_image_seconds = 0.0;   // loading or computing the key images' features
  std::string options_json = "{}";  // the localizer's options
  bool experiences = false;         // the map has experiences: frames say which one fitted
};

// What a run's file recorded of its map (ReadLocalizationRun), to tell a map built again since the run from the
// one it was made against: key indices alone fit a rebuilt map as well, and would pair frames with other images.
struct RunMapRecord {
  int key_images = -1;  // how many the map had; -1: not recorded
  // Per frame (as LocalizationRun::frames): the map frame of its key and next key image (-1: none), when recorded.
  std::vector<std::optional<std::pair<int, int>>> key_frames;
};

struct LocalizationRun {
  LocalizationRunInfo info;
  LocalizationSummary summary;
  std::vector<LocalizationResult> frames;
  RunMapRecord recorded_map;  // empty for a run made in this process
};

// The localizer's options as JSON text (for LocalizationRunInfo::options_json).
std::string DescribeLocalizerOptions(const LocalizerOptions& options);

// `experiences`: the map has experiences (adds their columns).
std::string LocalizationCsvHeader(bool experiences = false);
// One CSV row (with the newline) for `result`, localized against `map`.
std::string LocalizationCsvRow(const VisualMap& map, const LocalizationResult& result, bool experiences = false);

// One frame of a run as the JSON lists it (the CSV's columns, with F and the pose as lists); the Python module
// gives its results these names.
nlohmann::json LocalizationFrameJson(const VisualMap& map, const LocalizationResult& result, bool experiences = false);

// The JSON document of a run (frames listed in order).
std::string LocalizationRunJson(const VisualMap& map, const LocalizationRun& run);

// Reads a run written by LocalizationRunJson. Throws InputError naming the file when it is not one.
LocalizationRun ReadLocalizationRun(const std::filesystem::path& file);

// Throws InputError naming `file` (the run's) and the frame when a frame of `run` names a key image `map` does
// not have (its key, next key or a candidate's): a run of another map, or an edited file. Also when the run
// recorded a number of key images, or a frame's key_frame / next_key_frame, other than `map`'s: a map built again
// since the run.
void CheckRunFitsMap(const LocalizationRun& run, const VisualMap& map, const std::filesystem::path& file);

}  // namespace vmap
