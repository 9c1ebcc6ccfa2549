#pragma once
// Where LoFTR, XFeat and ALIKED weights are found, and how they get there (`vmap weights`). No LibTorch here.
//
// Search order for a preset, unless --weights names a file:
//   1. the cache directory: $VMAP_WEIGHTS_DIR if set, else $XDG_CACHE_HOME/vmap/weights, else ~/.cache/vmap/weights;
//   2. models shipped in the shared data folder (the Coarse-LoFTR student, XFeat folded, ALIKED T16/N16): that file
//      relative to the working directory (../shared/...), then under the data folder vmap was built with.

#include <string>
#include <vector>

namespace vmap::neural {

inline constexpr char kWeightsDirEnv[] = "VMAP_WEIGHTS_DIR";

struct KnownWeights {
  std::string preset;       // "outdoor", "indoor", "coarse" (LoFTR), "xfeat", "aliked-t16", "aliked-n16"
  std::string file_name;    // name in the cache directory
  std::string url;          // empty when `vmap weights --download` cannot fetch it
  std::string git_blob_id;  // of a published copy; empty when unknown
  std::string description;
  std::string shared_file;               // path under the shared data folder; empty when it is not shipped there
  std::string option = "--loftr-model";  // the command-line option that selects this preset
};

const std::vector<KnownWeights>& KnownWeightFiles();
const KnownWeights& KnownWeightsFor(const std::string& preset);  // throws InputError for unknown presets

std::string WeightsCacheDir();
std::vector<std::string> WeightsSearchPaths(const std::string& preset);

// The file to load: `explicit_path` if given (it must exist), else the first existing search path.
// Throws InputError naming every place searched and how to get the weights.
std::string LocateWeights(const std::string& preset, const std::string& explicit_path);

// Copies `source` into `cache_dir` as the preset's file, after checking its git blob id against
// `expected_blob_id` (skipped when empty). The copy appears atomically (temporary file + rename); on a
// mismatch nothing is written and InputError gives both ids. Returns the cached path.
std::string ImportWeights(const std::string& source, const std::string& preset, const std::string& expected_blob_id,
                          const std::string& cache_dir);

// Downloads the preset's file with curl or wget (whichever is installed) and imports it with its known id;
// `verify` false skips the id check. Throws InputError when no tool is installed or the download fails.
std::string DownloadWeights(const std::string& preset, const std::string& cache_dir, bool verify);

}  // namespace vmap::neural
