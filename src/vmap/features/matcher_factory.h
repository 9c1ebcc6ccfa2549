#pragma once
// Creates a matcher by name from the options of every matcher.

#include <memory>
#include <string>

#include "vmap/features/matcher.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/neural/aliked_options.h"
#include "vmap/neural/loftr_options.h"
#include "vmap/neural/xfeat_options.h"

namespace vmap {

struct MatcherOptions {
  std::string type = "orb";  // "orb", "loftr", "xfeat" or "aliked"
  OrbMatcherOptions orb;
  LoftrMatcherOptions loftr;
  XfeatMatcherOptions xfeat;
  AlikedMatcherOptions aliked;

  void Check() const;  // throws InputError naming the bad option
};

// The threshold tau `vmap build` uses with this matcher when --tau is not given. S = verified / tentative
// means something else for each matcher: ALIKED's mutual matches with a similarity floor stay ~80 % inliers
// while their number collapses, XFeat's keypoints fit F at 0.5 px less often than ORB's. Each value is the
// lowest tau of the sweeps in the README ("Deep features") whose maps keep >= 95 % usable links where ground
// truth exists, and a key image every few frames elsewhere. Throws InputError for an unknown type.
double DefaultTau(const std::string& matcher_type);

// Throws InputError when the matcher cannot be created (unknown type, a deep matcher without LibTorch, weights
// missing).
std::unique_ptr<Matcher> CreateMatcher(const MatcherOptions& options);

}  // namespace vmap
