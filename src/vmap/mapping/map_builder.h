#pragma once
// Builds visual maps: MapBuilder, the incremental builder around KeyImageSelector (frames pushed one at a
// time, their features extracted and compared ahead on worker threads, the map written through a MapWriter),
// and the batch calls over it (BuildMap, SweepThresholds).

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/features/matcher.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/mapping/link_analysis.h"
#include "vmap/map/visual_map.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// --threads accepts 0 (one per core) to this.
inline constexpr int kMaxExtractionThreads = 256;
// How Algorithm 1 looks for the next key image.
enum class KeySearch {
  kAuto,        // see ResolveKeySearch
  kSequential,  // every frame is compared with the key image, in order (Algorithm 1 as written)
  kBisect,      // frames ever further ahead are compared with the key image, then the first frame below tau is
                // found by bisection: the same key images wherever S decreases with the distance to the key
                // image, for far fewer comparisons (and feature extractions)
};
inline constexpr EnumName<KeySearch> kKeySearchNames[] = {
    {KeySearch::kAuto, "auto"}, {KeySearch::kSequential, "sequential"}, {KeySearch::kBisect, "bisect"}};
KeySearch ParseKeySearch(const std::string& name);
std::string KeySearchName(KeySearch search);

struct MapBuilderOptions {
  KeyImageOptions key_images;
  VerifierOptions verifier;
  QualityMean quality_mean = QualityMean::kArithmetic;
  LinkAnalysisOptions link_analysis;  // each link's pose, parallax and homography test, after selection
  bool show_progress = true;   // a progress line on a terminal
  int prefetch_frames = 6;     // frames read and extracted ahead of matching
  int extraction_threads = 0;  // threads extracting features; 0 = one per core, at most kMaxExtractionThreads
  // The paper's exact behaviour: every comparison verified by OpenCV's USAC_MAGSAC to its confidence criterion.
  // Off (the default), with the magsac verifier, a comparison stops as soon as S >= tau is settled for the taus
  // it is judged under (vmap's MAGSAC++, geometry/magsac.h) and each link is verified in full: the same maps
  // within the noise of a seed change, at a fraction of the cost (README, "Threshold sweeps" and "Speed").
  bool exhaustive = false;
  KeySearch key_search = KeySearch::kAuto;
  // kBisect: frames held at most (the furthest a comparison looks ahead); memory grows with it, comparisons
  // fall slowly as it grows.
  int search_window = 32;
  // BuildMap and SweepThresholds call it on the calling thread after each frame they read: a host polls for
  // its own interruption there (the Python module checks for Ctrl-C) and throws to abandon the build, which
  // then writes nothing more. Not recorded, like the other settings of how a run is carried out.
  std::function<void()> after_frame;

  int ExtractionThreads() const;

  void Check() const;  // throws OptionError naming the bad field
};

// kAuto resolves to kSequential, for every matcher (Check() refuses kBisect with `exhaustive`). Bisect was
// measured as the deep matchers' default and dropped (README, "Threshold sweeps": deep matchers): for XFeat it was no faster
// (0.90-1.04x on three of four sequences, more comparisons where S does not fall with distance), and for
// ALIKED, 1.5-10x faster, it changed the map on three of four sequences (its S stays high until its matches run
// out). It stays available as --search bisect.
KeySearch ResolveKeySearch(const MapBuilderOptions& options);

class JsonFieldReader;
// The builder's options as map.json records them, at the top level of "options" (a layout older than these
// structs): KeyImageOptions' fields, "verifier", "exhaustive", "search" (resolved: the search that ran),
// "search_window", "quality_mean", and LinkAnalysisOptions' "pose" and "homography". How a run is carried out
// (show_progress, prefetch_frames, extraction_threads) never changes its map and is not recorded.
nlohmann::json ToJson(const MapBuilderOptions& options);
// Reads a record written by ToJson; fields it lacks keep their values (core/json_fields.h).
void FromJson(const JsonFieldReader& fields, MapBuilderOptions* options);

// Every option that shaped a map: map.json's "options" (sweep.json's for a sweep), the builder's and the
// input's typed, the matcher's as the matcher describes itself (a model's record may hold derived values;
// features/matcher_options_json.h rebuilds its options).
struct RecordedOptions {
  std::string matcher_json = "{}";  // Matcher::DescribeOptionsJson()
  std::string matcher_type;         // its "type"; "" when not recorded
  MapBuilderOptions builder;
  FrameSourceOptions source;
};
// The builder's fields at the top level, "matcher" and "source" as objects.
nlohmann::json ToJson(const RecordedOptions& options);
// Reads a record (fields it lacks keep their defaults). Throws InputError naming `where` and the key of a
// value of the wrong kind or an enum name this vmap does not know.
RecordedOptions RecordedOptionsFromJson(const std::string& options_json, const std::string& where);

class MapWriter;

// Builds a map one frame at a time: Algorithm 1 with the sequential search, streaming, so that a live input
// (a camera, a network stream) gets a map while it runs (Snapshot) and at any end (Finish). Frames pushed with
// Add() go to `prefetch_frames` worker threads that extract their features and compare them with the key
// images ahead of Algorithm 1, which takes them in order; Add() returns once the frame is handed over (it waits
// only when that many frames are in flight), so the caller decodes the next frame meanwhile.
//
// With a MapWriter, the map is written through it: key images as they are chosen, evaluations to a file as
// they are made (memory stays flat for any length: the returned map's `evaluations` are then empty, map.json
// has them all), map.json and correspondences.bin at Finish. Without one, the map is only returned, with its
// evaluations in memory. The same options and frames give the same map as BuildMap, whatever the threads do.
class MapBuilder {
 public:
  // One map at options.key_images.tau. `source` gives the input's description (info(), skipped_frames()) as it
  // is known when a map is written; the frames come through Add(). Refuses key_search bisect (OptionError), which
  // reads ahead of the frames it is given.
  MapBuilder(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
             MapWriter* writer = nullptr, std::string options_json = "{}");
  // One map per threshold over one pass (a sweep): each frame's features are extracted once, and a pair compared
  // for several taus is matched once. writers[i] (may be null) receives tau i's map.
  MapBuilder(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
             std::vector<double> taus, std::vector<MapWriter*> writers, std::string options_json = "{}");
  ~MapBuilder();
  MapBuilder(const MapBuilder&) = delete;
  MapBuilder& operator=(const MapBuilder&) = delete;

  // The next frame of the input (in order).
  void Add(Frame frame);
  // Writes the map of the frames taken so far through each writer that has a snapshot target: a consistent map
  // (the key images chosen so far and their links, no final key image), committed atomically.
  void Snapshot();
  // Ends the input: the final key image, full link verification and analysis, each map written through its
  // writer. `end` is recorded in the map (VisualMap::coverage) when it is not kInputEnded, and for an input of
  // unknown length. `analyze_links` false skips each link's pose, parallax and homography test (sweep tables).
  // `with_evaluations`: the maps returned have their evaluations even when a writer took them (read back from
  // its file: the whole map in memory, for batch callers).
  std::vector<VisualMap> FinishAll(CoverageEnd end = CoverageEnd::kInputEnded, bool analyze_links = true,
                                   bool with_evaluations = false);
  VisualMap Finish(CoverageEnd end = CoverageEnd::kInputEnded);  // the one map

  long features_extracted() const;  // one per frame: no frame is extracted twice
  long pairs_matched() const;       // pairs matched and verified, including a few made ahead and not needed
  long links_verified() const;      // links verified in full after an early-stopped decision

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// Builds one map from a whole source and returns it with its evaluations in memory (a batch call for tests,
// benchmarks and tools; `vmap build` streams with MapBuilder). When `directory` (which must exist) is not empty,
// the whole map is also written there through a MapWriter: key images (keys/NNNNNN.png, or a copy of the
// frame's image file, keys/NNNNNN.jpg, ..., when the frame is that file as decoded), map.json and
// correspondences.bin. `options_json` is recorded verbatim in the map.
VisualMap BuildMap(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                   const std::filesystem::path& directory = {}, const std::string& options_json = "{}");

// One row of the paper's threshold table.
struct SweepRow {
  double tau = 0.0;
  int num_key_images = 0;
  double key_image_percent = 0.0;  // 100 m / n
  int min_verified = 0;
  int max_verified = 0;
  double mean_verified = 0.0;
  double mean_similarity = 0.0;
  double quality = 0.0;
  int below_tau_links = 0;
  int usable_links = -1;      // links usable against ground truth (vmap sweep --gt); -1 = not evaluated
  std::string map_directory;  // where the map for this tau was written, if it was
};

struct SweepResult {
  SequenceInfo input;
  std::string options_json;
  int num_frames = 0;
  std::vector<SweepRow> rows;
  int best_row = -1;           // highest Q
  double seconds = 0.0;
  long features_extracted = 0; // one per frame: no frame is extracted twice
  long pairs_matched = 0;      // pairs matched and verified, including a few made ahead and not needed
  long links_verified = 0;     // links verified in full after an early-stopped decision (not matched again)
};

// A sweep runs one key-image selector per threshold, all at once: at most this many.
inline constexpr int kMaxThresholds = 100;

// Parses "0.1:0.9:0.1" (start:stop:step, inclusive) or "0.2,0.5,0.8": 1 to kMaxThresholds distinct thresholds
// in (0, 1]. Malformed text is an OptionError naming "thresholds".
std::vector<double> ParseThresholds(const std::string& text);

// Runs every tau over one pass of the sequence (a MapBuilder with one selector per tau). Always compares every
// frame (kBisect is per tau: use BuildMap). When `maps_directory` is given, each tau's map is also written
// there, whole, as tau_0.50/ (the caller commits the parent atomically).
SweepResult SweepThresholds(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::vector<double>& taus, std::vector<VisualMap>* maps = nullptr,
                            const std::filesystem::path& maps_directory = {}, const std::string& options_json = "{}");

}  // namespace vmap
