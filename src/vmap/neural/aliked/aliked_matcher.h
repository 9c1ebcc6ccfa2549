#pragma once
// ALIKED behind the Matcher interface (`--matcher aliked`). No LibTorch in this header.

#include <memory>
#include <string>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/neural/aliked/aliked_options.h"

namespace vmap {

// Loads the model's weights (see weights_store.h for where they are searched) and checks every key and shape.
// Throws InputError for missing or mismatched weights and for --device cuda without CUDA.
// Extract runs the network on the grey image (as its three identical channels), ExtractFrame on the colour
// image when there is one (its R, G, B channels, as upstream's demo), at its own size unless
// options.longest_side shrinks it; detects keypoints with DKD and describes them with SDDH; keypoints are in
// pixels of the image given to Extract (OpenCV convention: pixel centres at integers). Match keeps mutual
// nearest neighbours of the descriptors with cosine similarity >= options.min_similarity (scores = the
// similarity). Extract and Match may run concurrently on different threads.
std::unique_ptr<Matcher> CreateAlikedMatcher(const AlikedMatcherOptions& options);

// The ALIKED models ("t16", "n16") a weights file fits exactly (reads the whole file). Throws InputError for
// unreadable files, with the same messages as CreateAlikedMatcher.
std::vector<std::string> AlikedModelsFittingFile(const std::string& path);

}  // namespace vmap
