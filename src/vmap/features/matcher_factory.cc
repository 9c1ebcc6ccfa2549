#include "vmap/features/matcher_factory.h"

#include "vmap/core/error.h"
#include "vmap/neural/torch_plugin.h"

namespace vmap {

void MatcherOptions::Check() const {
  if (type != "orb" && type != "loftr" && type != "xfeat" && type != "aliked")
    throw InputError("unknown matcher '" + type + "'; use orb, loftr, xfeat or aliked");
  // The options of every matcher, used or not: an absurd value (NaN, out of range) is a mistake either way.
  orb.Check();
  loftr.Check();
  xfeat.Check();
  aliked.Check();
}

double DefaultTau(const std::string& matcher_type) {
  if (matcher_type == "orb") return 0.5;     // the paper's tables' middle; README "The method, exactly"
  if (matcher_type == "xfeat") return 0.4;
  if (matcher_type == "aliked") return 0.7;
  if (matcher_type == "loftr") return 0.5;
  throw InputError("unknown matcher '" + matcher_type + "'; use orb, loftr, xfeat or aliked");
}

std::unique_ptr<Matcher> CreateMatcher(const MatcherOptions& options) {
  options.Check();
  if (options.type == "orb") return CreateOrbMatcher(options.orb);
#ifdef VMAP_WITH_TORCH
  if (options.type == "xfeat") return TorchPlugin().create_xfeat_matcher(options.xfeat);
  if (options.type == "aliked") return TorchPlugin().create_aliked_matcher(options.aliked);
  return TorchPlugin().create_loftr_matcher(options.loftr);
#else
  throw InputError("this vmap was built without LibTorch (VMAP_WITH_TORCH=OFF); rebuild with it for --matcher " +
                   options.type);
#endif
}

}  // namespace vmap
