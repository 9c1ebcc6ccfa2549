#pragma once
// Options of the XFeat matcher (`--matcher xfeat`). This header does not include LibTorch, so any stage may
// use it.

#include <string>

#include "vmap/core/option_fields.h"

namespace vmap {

struct XfeatMatcherOptions {
  static constexpr const char* kModelName = "xfeat";  // --matcher xfeat (features/matcher_registry.h)
  std::string weights;         // file; empty searches the weights directories (see `vmap weights`)
  std::string device = "cpu";  // "cpu" or "cuda"
  // Keypoints kept per image, the best by score (upstream's default is 4096). Fewer keypoints make matching
  // (quadratic in top_k) and MAGSAC cheaper; docs/measurements/deep-matchers.md has the measured choice.
  int top_k = 4096;
  // A keypoint needs a heatmap value above this (upstream 0.05).
  double detection_threshold = 0.05;
  // Mutual nearest neighbours are kept when their cosine similarity exceeds this (strictly, as upstream's
  // XFeat.match, whose default is 0.82). <= 0 keeps every mutual pair, as upstream (match_xfeat uses -1).
  double min_similarity = 0.82;
  // LibTorch threads per Extract call; 0 keeps LibTorch's default. vmap build already extracts frames on one
  // worker per core, where more threads per call only oversubscribe the cores.
  int num_threads = 1;

  void Check() const;                             // throws OptionError naming the bad field
  void VisitFields(OptionFieldVisitor& visitor);  // JSON keys and command-line flags
};

}  // namespace vmap
