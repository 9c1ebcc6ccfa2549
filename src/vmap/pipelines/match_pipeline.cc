#include "vmap/pipelines/match_pipeline.h"

#include "vmap/core/error.h"

namespace vmap {

void PairMatchOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.VisitNested("heading", heading);
  visitor.VisitNested("", matcher);
  visitor.VisitNested("verifier", verifier, Nesting{false, {"max_samples_to_reject"}});
}

void PairMatchOptions::Check() const {
  CheckField("verifier", verifier);
  matcher.Check();
  CheckField("heading", heading);
}

}  // namespace vmap
