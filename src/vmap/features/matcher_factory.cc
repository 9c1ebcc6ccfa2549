#include "vmap/features/matcher_factory.h"

#include "vmap/core/error.h"
#include "vmap/neural/torch_plugin.h"

namespace vmap {

void MatcherOptions::Check() const {
  if (type == "orb") orb.Check();
  else if (type == "loftr") loftr.Check();
  else if (type == "aliked") aliked.Check();
  else throw InputError("unknown matcher '" + type + "'; use orb, loftr or aliked");
}

std::unique_ptr<Matcher> CreateMatcher(const MatcherOptions& options) {
  options.Check();
  if (options.type == "orb") return CreateOrbMatcher(options.orb);
#ifdef VMAP_WITH_TORCH
  if (options.type == "aliked") return TorchPlugin().create_aliked_matcher(options.aliked);
  return TorchPlugin().create_loftr_matcher(options.loftr);
#else
  throw InputError("this vmap was built without LibTorch (VMAP_WITH_TORCH=OFF); rebuild with it for --matcher " +
                   options.type);
#endif
}

}  // namespace vmap
