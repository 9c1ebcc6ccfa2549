#pragma once
// LoFTR behind the Matcher interface (`--matcher loftr`). No LibTorch in this header.

#include <memory>
#include <string>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/neural/loftr/loftr_options.h"

namespace vmap {

// Loads the preset's weights (see weights_store.h for where they are searched) and checks every key and
// shape. Throws InputError for missing or mismatched weights and for --device cuda without CUDA.
// Extract resizes the image so both sides are multiples of the coarse stride (longest side
// options.longest_side) and runs the backbone once; Match runs the transformers and the matching. Points
// are mapped back to the image given to Extract; the coarse student's points are the top-left corners of
// its 16x16 cells, as upstream reports them. Extract and Match may run concurrently on different threads.
std::unique_ptr<Matcher> CreateLoftrMatcher(const LoftrMatcherOptions& options);

}  // namespace vmap

namespace vmap {

// The presets whose architecture a weights file fits exactly (reads the whole file). Throws InputError for
// unreadable files, with the same messages as CreateLoftrMatcher.
std::vector<std::string> LoftrPresetsFittingFile(const std::string& path);

}  // namespace vmap
