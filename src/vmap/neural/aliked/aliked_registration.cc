// ALIKED in the matcher registry (features/matcher_registry.h); the plugin creates it (aliked_matcher.cc).

#include "vmap/features/matcher_registry.h"
#include "vmap/neural/aliked/aliked_options.h"

namespace vmap {
namespace {

const MatcherModelRegistration kAliked{[] {
  MatcherModel model = MatcherModel::Of<AlikedMatcherOptions>(
      "ALIKED (LibTorch): keypoints and descriptors with deformable convolutions, mutual nearest neighbours", 0.7);
  model.needs_torch = true;
  return model;
}()};

}  // namespace
}  // namespace vmap
