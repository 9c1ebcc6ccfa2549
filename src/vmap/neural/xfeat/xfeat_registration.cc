// XFeat in the matcher registry (features/matcher_registry.h); the plugin creates it (xfeat_matcher.cc).

#include "vmap/features/matcher_registry.h"
#include "vmap/neural/xfeat/xfeat_options.h"

namespace vmap {
namespace {

const MatcherModelRegistration kXfeat{[] {
  MatcherModel model = MatcherModel::Of<XfeatMatcherOptions>(
      "XFeat (LibTorch): light keypoints and descriptors, mutual nearest neighbours", 0.4);
  model.needs_torch = true;
  return model;
}()};

}  // namespace
}  // namespace vmap
