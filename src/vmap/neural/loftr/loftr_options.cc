#include "vmap/neural/loftr/loftr_options.h"

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
}

void LoftrMatcherOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"model", "--loftr-model", "LoFTR preset: outdoor, indoor or coarse"}, model);
  visitor.Visit({"weights", "--weights", "Weights file of the deep matcher (see `vmap weights`)", false, true},
                weights);
  visitor.Visit({"device", "--device", "Deep matchers' device: cpu or cuda"}, device);
  visitor.Visit(
      OptionField{"longest_side", "--loftr-size", "LoFTR: longest image side fed to the network"}.Within(32, 4096),
      longest_side);
  // 0 is taken: it keeps every mutual nearest neighbour (used to reproduce the random-weight golden).
  visitor.Visit(
      OptionField{"threshold", "--loftr-threshold", "LoFTR: coarse confidence threshold (below 0 = the preset's)"}
          .Within(-1, 1)
          .Meaning("below 0: the preset's")
          .HideDefault(),
      threshold);
  visitor.Visit(OptionField{"threads", "--loftr-threads", "LoFTR: LibTorch threads per call (0 = LibTorch default)"}
                    .Within(0, 256)
                    .Meaning("0: LibTorch's default"),
                num_threads);
}

}  // namespace vmap
