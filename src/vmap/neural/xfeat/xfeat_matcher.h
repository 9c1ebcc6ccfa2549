#pragma once
// XFeat behind the Matcher interface (`--matcher xfeat`). No LibTorch in this header.

#include <memory>
#include <string>

#include "vmap/features/matcher.h"
#include "vmap/neural/xfeat/xfeat_options.h"

namespace vmap {

// Loads the weights (either layout; see xfeat_weights.h and, for where they are searched, weights_store.h)
// and checks every key and shape. Throws InputError for missing or mismatched weights and for --device cuda
// without CUDA. Extract runs upstream's detectAndCompute on the grey image (resized to multiples of 32 for
// the network, keypoints mapped back to the image given); Match keeps the mutual nearest neighbours whose
// cosine similarity exceeds options.min_similarity. Extract and Match may run concurrently on different
// threads.
std::unique_ptr<Matcher> CreateXfeatMatcher(const XfeatMatcherOptions& options);

// The layout of an XFeat weights file: "folded" or "official" (reads and checks the whole file). Throws
// InputError, with the same messages as CreateXfeatMatcher, for unreadable files and files of another model.
std::string XfeatWeightsLayoutOfFile(const std::string& path);

}  // namespace vmap
