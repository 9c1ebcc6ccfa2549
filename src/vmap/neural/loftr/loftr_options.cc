#include "vmap/neural/loftr/loftr_options.h"

#include <cmath>

#include <fmt/format.h>

#include "vmap/core/error.h"

namespace vmap {

void LoftrMatcherOptions::Check() const {
  const LoftrMatcherOptions defaults;  // the defaults the messages give, as declared
  if (model != "outdoor" && model != "indoor" && model != "coarse") {
    throw OptionError("model", "'" + model + "' is not a LoFTR model; use outdoor, indoor or coarse");
  }
  if (device != "cpu" && device != "cuda") {
    throw OptionError("device", "'" + device + "' is not a device; use cpu or cuda");
  }
  if (longest_side < 32 || longest_side > 4096) {
    throw OptionError("longest_side",
                      fmt::format("{} is outside 32 to 4096 (default {})", longest_side, defaults.longest_side));
  }
  if (num_threads < 0 || num_threads > 256) {
    throw OptionError("threads", "must be 0 to 256 (0 = LibTorch's default)");
  }
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
  visitor.Visit({"longest_side", "--loftr-size", "LoFTR: longest image side fed to the network"}, longest_side);
  visitor.Visit({"threshold", "--loftr-threshold", "LoFTR: coarse confidence threshold (default: preset's)", false},
                threshold);
  visitor.Visit({"threads", "--loftr-threads", "LoFTR: LibTorch threads per call (0 = LibTorch default)"}, num_threads);
}

}  // namespace vmap
