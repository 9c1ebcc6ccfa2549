// LoFTR in the matcher registry (features/matcher_registry.h); the plugin creates it (loftr_matcher.cc).

#include "vmap/features/matcher_registry.h"
#include "vmap/neural/loftr/loftr_options.h"

namespace vmap {
namespace {

const MatcherModelRegistration kLoftr{[] {
  MatcherModel model = MatcherModel::Of<LoftrMatcherOptions>(
      "LoFTR (LibTorch): detector-free matching by transformers on coarse and fine features", 0.5);
  model.needs_torch = true;
  return model;
}()};

}  // namespace
}  // namespace vmap
