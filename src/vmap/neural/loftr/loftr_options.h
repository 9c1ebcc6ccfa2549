#pragma once
// Options of the LoFTR matcher. This header does not include LibTorch, so any stage may use it.

#include <string>

#include "vmap/core/option_fields.h"

namespace vmap {

struct LoftrMatcherOptions {
  static constexpr const char* kModelName = "loftr";  // --matcher loftr (features/matcher_registry.h)
  std::string model = "coarse";                       // preset: "outdoor", "indoor" or "coarse"
  std::string weights;         // file; empty searches the weights directories (see `vmap weights`)
  std::string device = "cpu";  // "cpu" or "cuda"
  int longest_side = 640;      // images are resized to this longest side (multiple of the coarse stride)
  double threshold = -1;       // coarse confidence threshold; < 0 uses the preset's
  // LibTorch threads per Extract/Match call; 0 keeps LibTorch's default. vmap build already extracts frames
  // on several threads at once, where more threads per call only oversubscribe the cores.
  int num_threads = 0;

  void Check() const;                             // throws OptionError naming the bad field
  void VisitFields(OptionFieldVisitor& visitor);  // JSON keys and command-line flags
};

}  // namespace vmap
