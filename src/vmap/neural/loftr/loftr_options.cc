#include "vmap/neural/loftr/loftr_options.h"

#include <cmath>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void LoftrMatcherOptions::Check() const {
  if (model != "outdoor" && model != "indoor" && model != "coarse") {
    throw OptionError("model", "'" + model + "' is not a LoFTR model; use outdoor, indoor or coarse");
  }
  if (device != "cpu" && device != "cuda") {
    throw OptionError("device", "'" + device + "' is not a device; use cpu or cuda");
  }
  CheckFieldRanges(*this);
  if (!std::isfinite(threshold) || threshold > 1.0) {
    // 0 is allowed: it keeps every mutual nearest neighbour (used to reproduce the random-weight golden).
    throw OptionError("threshold", "must be in [0, 1] (negative: the preset's)");
  }
}

void LoftrMatcherOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"model", "--loftr-model", "LoFTR preset: outdoor, indoor or coarse"}, model);
  visitor.Visit({"weights", "--weights", "Weights file of the deep matcher (see `vmap weights`)", false, true},
                weights);
  visitor.Visit({"device", "--device", "Deep matchers' device: cpu or cuda"}, device);
  visitor.Visit(
      OptionField{"longest_side", "--loftr-size", "LoFTR: longest image side fed to the network"}.Within(32, 4096),
      longest_side);
  visitor.Visit({"threshold", "--loftr-threshold", "LoFTR: coarse confidence threshold (default: preset's)", false},
                threshold);
  visitor.Visit(OptionField{"threads", "--loftr-threads", "LoFTR: LibTorch threads per call (0 = LibTorch default)"}
                    .Within(0, 256)
                    .Meaning("0: LibTorch's default"),
                num_threads);
}

}  // namespace vmap
