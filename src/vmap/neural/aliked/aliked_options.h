#pragma once
// Options of the ALIKED matcher (`--matcher aliked`). This header does not include LibTorch, so any stage may
// use it.

#include <string>

#include "vmap/core/option_fields.h"

namespace vmap {

struct AlikedMatcherOptions {
  static constexpr const char* kModelName = "aliked";  // --matcher aliked (features/matcher_registry.h)
  std::string model = "t16";                           // "t16" (ALIKED-T16) or "n16" (ALIKED-N16)
  std::string weights;         // file; empty searches the weights directories (see `vmap weights`)
  std::string device = "cpu";  // "cpu" or "cuda"
  // Keypoints per image: the top_k highest DKD scores. 0 switches to upstream's threshold mode: every NMS
  // peak whose score exceeds score_threshold, at most max_keypoints of them (the upstream demos' mode).
  // 1000 keypoints gave the best maps of the measured settings (docs/matchers.md, ALIKED); more cost matching and
  // MAGSAC time without more usable links.
  int top_k = 1000;
  double score_threshold = 0.2;  // threshold mode only (upstream default)
  int max_keypoints = 5000;      // threshold mode only (upstream n_limit)
  // Mutual nearest neighbours with a cosine similarity of at least this are tentative matches. Upstream's
  // demos use 0.75 for pairs and 0.9 for sequences; docs/matchers.md has the measurement behind the default.
  double min_similarity = 0.75;
  // Images are processed at their own size (replicate-padded to a multiple of 32, as upstream). A value > 0
  // first shrinks images whose longest side exceeds it (INTER_AREA), for speed; keypoints are mapped back.
  int longest_side = 0;
  // LibTorch threads per Extract call; 0 keeps LibTorch's default. vmap build already extracts frames on
  // one worker per core, where more threads per call only oversubscribe the cores.
  int num_threads = 1;

  void Check() const;                             // throws OptionError naming the bad field
  void VisitFields(OptionFieldVisitor& visitor);  // JSON keys and command-line flags
  void AfterReading();                            // after reading a map: older maps name the model aliked-t16
};

}  // namespace vmap
