#pragma once
// One image pair through a matcher and the verifier (`vmap match IMAGE0 IMAGE1`, vmap.match, vmap.Matcher):
// the options that set the pair's matching up.

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/heading.h"

namespace vmap {

struct PairMatchOptions {
  HeadingOptions heading;
  MatcherOptions matcher;
  // Verified in full (one pair: no early stop, so no max_samples_to_reject).
  VerifierOptions verifier;

  // The fields above, each once ("heading.min_votes", "matcher", "orb.num_features", "verifier.threshold").
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

}  // namespace vmap
