#include "vmap/localization/route_evidence.h"

#include <algorithm>
#include <cmath>

namespace vmap {

// The coefficients as bench/evidence_fit.py fitted them (docs/localize.md, "The belief over the route").
EvidenceModel BinaryDescriptorEvidence() { return {-1.0, 1.59, 0.383, 1.52, -15.0, 40.0}; }
EvidenceModel FloatDescriptorEvidence() { return {-1.0, -2.66, 0.086, 3.75, -15.0, 40.0}; }

double EvidenceLogRatio(const EvidenceModel& model, const KeyComparison& comparison, int link_verified) {
  if (!comparison.matched) return model.unmatched;
  const double significance = std::clamp(-comparison.log10_nfa, model.min_significance, model.max_significance);
  const double share =
      link_verified > 0 ? std::min(1.0, static_cast<double>(comparison.num_verified) / link_verified) : 0.0;
  return model.intercept + model.per_significance * significance + model.per_link_share * share;
}

}  // namespace vmap
