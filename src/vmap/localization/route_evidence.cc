#include "vmap/localization/route_evidence.h"

#include <algorithm>
#include <cmath>

namespace vmap {

// The coefficients as bench/evidence_fit.py fitted them (docs/localize.md, "The belief over the route"; the ranking's:
// "The ranking is evidence", bench/evidence_fit.py --rank).
EvidenceModel BinaryDescriptorEvidence() {
  EvidenceModel model{-1.0, 1.59, 0.383, 1.52, -15.0, 40.0};
  model.heading_stands_out = 3.0;
  return model;
}
EvidenceModel FloatDescriptorEvidence() {
  EvidenceModel model{-1.0, -2.66, 0.086, 3.75, -15.0, 40.0};
  model.rank_alone = {3.22, 1.53, 0.86, 0.19, -1.15};
  model.rank_given = {3.51, 2.09, 1.54, 1.00, 0.0};
  model.ranked_intercept = -2.76;
  model.ranked_per_significance = 0.024;
  model.ranked_per_link_share = 3.24;
  return model;
}

int RankBucket(int rank) { return rank <= 0 ? 0 : rank <= 2 ? 1 : rank <= 4 ? 2 : rank <= 9 ? 3 : 4; }

double EvidenceLogRatio(const EvidenceModel& model, const KeyComparison& comparison, int link_verified, int rank) {
  if (!comparison.matched) return model.unmatched;
  const double significance = std::clamp(-comparison.log10_nfa, model.min_significance, model.max_significance);
  const double share =
      link_verified > 0 ? std::min(1.0, static_cast<double>(comparison.num_verified) / link_verified) : 0.0;
  if (rank < 0 || model.rank_alone.empty()) {
    return model.intercept + model.per_significance * significance + model.per_link_share * share;
  }
  const int bucket = RankBucket(rank);
  return model.ranked_intercept + model.ranked_per_significance * significance + model.ranked_per_link_share * share +
         model.rank_given[bucket] - model.rank_alone[bucket];
}

double RankLogRatio(const EvidenceModel& model, int rank) {
  return model.rank_alone.empty() ? 0.0 : model.rank_alone[RankBucket(rank)];
}

}  // namespace vmap
