#include "vmap/localization/route_evidence.h"

#include <algorithm>
#include <cmath>

namespace vmap {

// The coefficients as bench/evidence_fit.py fitted them (docs/localize.md, "The belief over the route"; the ranking's:
// "The ranking is evidence", bench/evidence_fit.py --rank).
EvidenceModel BinaryDescriptorEvidence() {
  EvidenceModel model;
  model.unmatched = -1.0;
  model.intercept = 1.59;
  model.per_significance = 0.383;
  model.per_link_share = 1.52;
  model.min_significance = -15.0;
  model.max_significance = 40.0;
  model.heading_stands_out = 3.0;
  // By standout, fitted on corridor_conditions (bench/evidence_fit.py --rank --rank-by standout; michigan's 5-place
  // routes measure -0.82 / +0.32 / +1.14 / +2.15 / +3.40 alike).
  model.standout_edges = {0.5, 1.5, 2.5, 3.5};
  model.rank_alone = {-1.11, 0.31, 0.98, 1.77, 3.14};
  model.rank_given = {0.0, 1.43, 1.96, 2.51, 2.79};
  model.ranked_intercept = -0.392;
  model.ranked_per_significance = 0.303;
  model.ranked_per_link_share = 2.524;
  model.rank_weight = 0.5;
  model.ranking_moves_own_frame = false;
  return model;
}
EvidenceModel FloatDescriptorEvidence() {
  EvidenceModel model = FloatDescriptorEvidenceByRank();
  // By standout, as ORB's, fitted on corridor_conditions (bench/evidence_fit.py --rank --rank-by standout --lo -15 --hi
  // 40): a key image ranked first on a dark frame whose votes barely stand out (65 against 62, 61, ... and a median
  // near 50) was weighed as one far above the rest (+3.22 by rank), and one frame's ranking moved the belief to the
  // route's end (docs/measurements/localization-conditions.md, "XFeat over the verifier's seeds 4-7, and three rules
  // measured, none kept", rule 3).
  model.standout_edges = {0.5, 1.5, 2.5, 3.5};
  model.rank_alone = {-1.34, 0.22, 0.84, 1.91, 4.19};
  model.rank_given = {0.0, 1.32, 1.76, 2.64, 4.74};
  model.ranked_intercept = -2.799;
  model.ranked_per_significance = 0.013;
  model.ranked_per_link_share = 3.052;
  return model;
}
EvidenceModel FloatDescriptorEvidenceByRank() {
  EvidenceModel model;
  model.unmatched = -1.0;
  model.intercept = -2.66;
  model.per_significance = 0.086;
  model.per_link_share = 3.75;
  model.min_significance = -15.0;
  model.max_significance = 40.0;
  model.rank_alone = {3.22, 1.53, 0.86, 0.19, -1.15};
  model.rank_given = {3.51, 2.09, 1.54, 1.00, 0.0};
  model.ranked_intercept = -2.76;
  model.ranked_per_significance = 0.024;
  model.ranked_per_link_share = 3.24;
  return model;
}

int RankBucket(int rank) { return rank <= 0 ? 0 : rank <= 2 ? 1 : rank <= 4 ? 2 : rank <= 9 ? 3 : 4; }

std::vector<int> RankingBuckets(const EvidenceModel& model, const std::vector<RankedKey>& ranked, int positions) {
  std::vector<int> buckets(positions, -1);
  if (model.rank_alone.empty() || ranked.empty()) return buckets;
  if (model.standout_edges.empty()) {
    for (size_t r = 0; r < ranked.size(); ++r) buckets[ranked[r].key] = RankBucket(static_cast<int>(r));
    return buckets;
  }
  // The ranking is best first: its median is read off it (the mean of the two middle ones for an even count).
  const size_t n = ranked.size();
  const double median = 0.5 * (ranked[(n - 1) / 2].score + ranked[n / 2].score);
  if (median <= 0.0) return buckets;
  for (const RankedKey& r : ranked) {
    const double standout = (r.score - median) / std::sqrt(median);
    buckets[r.key] = static_cast<int>(std::count_if(model.standout_edges.begin(), model.standout_edges.end(),
                                                    [&](double e) { return standout >= e; }));
  }
  return buckets;
}

double EvidenceLogRatio(const EvidenceModel& model, const KeyComparison& comparison, int link_verified, int bucket) {
  if (!comparison.matched) return model.unmatched;
  const double significance = std::clamp(-comparison.log10_nfa, model.min_significance, model.max_significance);
  const double share =
      link_verified > 0 ? std::min(1.0, static_cast<double>(comparison.num_verified) / link_verified) : 0.0;
  const double alone = model.intercept + model.per_significance * significance + model.per_link_share * share;
  if (bucket < 0 || model.rank_alone.empty()) return alone;
  const double given = model.ranked_intercept + model.ranked_per_significance * significance +
                       model.ranked_per_link_share * share + model.rank_given[bucket] - model.rank_alone[bucket];
  if (model.rank_weight >= 1.0) return given;
  return model.rank_weight * given + (1.0 - model.rank_weight) * alone;
}

double RankLogRatio(const EvidenceModel& model, int bucket) {
  return model.rank_alone.empty() || bucket < 0 ? 0.0 : model.rank_weight * model.rank_alone[bucket];
}

}  // namespace vmap
