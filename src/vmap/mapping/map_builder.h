#pragma once
// Builds visual maps from a frame source: the streaming loop around KeyImageSelector. Frames are read
// and their features extracted on a second thread while the main thread matches and verifies.

#include <filesystem>
#include <string>
#include <vector>

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
KeySearch ParseKeySearch(const std::string& name);  // "auto", "sequential", "bisect"
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

  int ExtractionThreads() const;

  void Check() const;  // throws InputError naming the bad option
};

// kAuto resolves to kSequential, for every matcher (Check() refuses kBisect with `exhaustive`). Bisect was
// measured as the deep matchers' default and dropped (README, "Threshold sweeps": deep matchers): for XFeat it was no faster
// (0.90-1.04x on three of four sequences, more comparisons where S does not fall with distance), and for
// ALIKED, 1.5-10x faster, it changed the map on three of four sequences (its S stays high until its matches run
// out). It stays available as --search bisect.
KeySearch ResolveKeySearch(const MapBuilderOptions& options);

// Builds one map. When `directory` (which must exist) is not empty, each key image is written there as soon as it is chosen,
// as keys/NNNNNN.png, or as a copy of its image file (keys/NNNNNN.jpg, ...) when the frame is that file as
// decoded (the caller writes map.json with WriteMapFiles).
// `options_json` is recorded verbatim in the map.
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
// in (0, 1].
std::vector<double> ParseThresholds(const std::string& text);

// Runs every tau over one pass of the sequence: each frame's features are extracted once, and a pair
// compared for several taus is matched once. Always compares every frame (kBisect is per tau: use BuildMap). When `maps_directory` is given, each tau's map is also
// written there as tau_0.50/ (the caller commits the parent atomically).
SweepResult SweepThresholds(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::vector<double>& taus, std::vector<VisualMap>* maps = nullptr,
                            const std::filesystem::path& maps_directory = {}, const std::string& options_json = "{}");

}  // namespace vmap
