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

// Throws InputError when the matcher cannot be created (unknown type, a deep matcher without LibTorch, weights
// missing).
std::unique_ptr<Matcher> CreateMatcher(const MatcherOptions& options);

}  // namespace vmap
