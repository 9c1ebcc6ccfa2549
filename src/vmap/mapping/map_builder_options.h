#pragma once
// How a map is built: MapBuilderOptions (key images, verifier, link analysis, the key-image search and how a
// run is carried out), and their record in map.json.

#include <functional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/features/matcher.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/mapping/link_analysis.h"

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
  bool show_progress = true;          // a progress line on a terminal
  int prefetch_frames = 6;            // frames read and extracted ahead of matching
  int extraction_threads = 0;         // threads extracting features; 0 = one per core, at most kMaxExtractionThreads
  // The paper's exact behaviour: every comparison verified by OpenCV's USAC_MAGSAC to its confidence criterion.
  // Off (the default), with the magsac verifier, a comparison stops as soon as S >= tau is settled for the taus
  // it is judged under (vmap's MAGSAC++, geometry/magsac.h) and each link is verified in full: the same maps
  // within the noise of a seed change, at a fraction of the cost (docs/measurements/sweeps.md and speed.md).
  bool exhaustive = false;
  KeySearch key_search = KeySearch::kAuto;
  // kBisect: frames held at most (the furthest a comparison looks ahead); memory grows with it, comparisons
  // fall slowly as it grows.
  int search_window = 32;
  // BuildMap and SweepThresholds call it on the calling thread after each frame they read: a host polls for
  // its own interruption there (the Python module checks for Ctrl-C) and throws to abandon the build, which
  // then writes nothing more. Not recorded, like the other settings of how a run is carried out.
  std::function<void()> after_frame;

  // The builder's options as map.json records them, at the top level of "options" (a layout older than these
  // structs): KeyImageOptions' fields, "verifier", "exhaustive", "search", "search_window", "quality_mean",
  // and LinkAnalysisOptions' "pose", "homography" and "translation". How a run is carried out (show_progress,
  // prefetch_frames, extraction_threads) never changes its map and is not recorded; extraction_threads has
  // its flag. The map records the search that ran (RecordedOptions resolves kAuto).
  void VisitFields(OptionFieldVisitor& visitor);
  int ExtractionThreads() const;

  void Check() const;  // throws OptionError naming the bad field
};

// kAuto resolves to kSequential, for every matcher (Check() refuses kBisect with `exhaustive`). Bisect was measured as
// the deep matchers' default and dropped (docs/measurements/deep-matchers.md, "Comparing fewer frames";
// docs/measurements/code-choices.md): for XFeat it was no faster (more comparisons where S does not fall with
// distance), and for ALIKED, though faster, it changed the map on three of four sequences (its S stays high until
// its matches run out). It stays available as --search bisect.
KeySearch ResolveKeySearch(const MapBuilderOptions& options);

// The verifier of the decisions: vmap's MAGSAC++, stopping once S >= tau is settled, unless the paper's
// exact behaviour is asked for (or another verifier, which OpenCV runs to its confidence criterion).
VerifierOptions DecisionVerifier(const MapBuilderOptions& options);

}  // namespace vmap
