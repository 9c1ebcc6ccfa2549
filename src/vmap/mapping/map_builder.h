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
#include "vmap/mapping/visual_map.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// --threads accepts 0 (one per core) to this.
inline constexpr int kMaxExtractionThreads = 256;

struct MapBuilderOptions {
  KeyImageOptions key_images;
  VerifierOptions verifier;
  QualityMean quality_mean = QualityMean::kArithmetic;
  LinkAnalysisOptions link_analysis;  // each link's pose, parallax and homography test, after selection
  bool show_progress = true;   // a progress line on a terminal
  int prefetch_frames = 6;     // frames read and extracted ahead of matching
  int extraction_threads = 0;  // threads extracting features; 0 = one per core, at most kMaxExtractionThreads

  int ExtractionThreads() const;

  void Check() const;  // throws InputError naming the bad option
};

// Builds one map. When `directory` (which must exist) is not empty, each key image is written there as
// keys/NNNNNN.png as soon as it is chosen (the caller writes map.json with WriteMapFiles).
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
};

// A sweep runs one key-image selector per threshold, all at once: at most this many.
inline constexpr int kMaxThresholds = 100;

// Parses "0.1:0.9:0.1" (start:stop:step, inclusive) or "0.2,0.5,0.8": 1 to kMaxThresholds distinct thresholds
// in (0, 1].
std::vector<double> ParseThresholds(const std::string& text);

// Runs every tau over one pass of the sequence: each frame's features are extracted once, and a pair
// compared for several taus is matched once. When `maps_directory` is given, each tau's map is also
// written there as tau_0.50/ (the caller commits the parent atomically).
SweepResult SweepThresholds(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::vector<double>& taus, std::vector<VisualMap>* maps = nullptr,
                            const std::filesystem::path& maps_directory = {}, const std::string& options_json = "{}");

}  // namespace vmap
