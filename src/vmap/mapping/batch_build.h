#pragma once
// Maps built from a whole source at once: BuildMap (one map) and SweepThresholds (one map per threshold, the
// paper's threshold table), on MapBuilder.

#include <filesystem>
#include <string>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/map_builder_options.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

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
  int best_row = -1;  // highest Q
  double seconds = 0.0;
  long features_extracted = 0;  // one per frame: no frame is extracted twice
  long pairs_matched = 0;       // pairs matched and verified, including a few made ahead and not needed
  long links_verified = 0;      // links verified in full after an early-stopped decision (not matched again)
};

// Runs every tau over one pass of the sequence (a MapBuilder with one selector per tau). Always compares every
// frame (kBisect is per tau: use BuildMap). When `maps_directory` is given, each tau's map is also written
// there, whole, as tau_0.50/ (the caller commits the parent atomically).
SweepResult SweepThresholds(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::vector<double>& taus, std::vector<VisualMap>* maps = nullptr,
                            const std::filesystem::path& maps_directory = {}, const std::string& options_json = "{}");

}  // namespace vmap
