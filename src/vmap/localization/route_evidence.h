#pragma once
// What one comparison of a frame with a key image says about whether the frame is there: the log of the ratio of
// its likelihood at a right key image (one bracketing the frame) to its likelihood at a wrong one, the weight
// RouteBelief::Weigh gives it.
//
// It grows with how unlikely the verified matches are by chance (s = -log10 of their number of false alarms,
// acceptance.h) and with their share of the verified matches of the key image's own link in the map (the same
// place, not only the same scene). How much each says depends on the matcher: ORB's chance model separates right
// from wrong key images across lighting (a wrong one rarely reaches s = -1), XFeat's many clustered matches pass
// it at wrong key images too, where the link share and a much higher s tell them apart. So there is one model per
// kind of descriptor, fitted by logistic regression on every frame of corridor_conditions (and michigan_seasons)
// against every key image of their maps (bench/evidence_dump, bench/evidence_fit.py; the fit and the false
// acceptance rates: docs/localize.md, "The belief over the route").

#include <vector>

#include "vmap/localization/key_comparison.h"

namespace vmap {

struct EvidenceModel {
  double unmatched = 0.0;         // the log ratio of a comparison without a verified F
  double intercept = 0.0;         // of a matched one: intercept + per_significance * s + per_link_share * share
  double per_significance = 0.0;  // s clamped to [min_significance, max_significance]
  double per_link_share = 0.0;    // share clamped to [0, 1]
  double min_significance = 0.0;
  double max_significance = 0.0;

  // Where the frame was ranked (KeyImageRanking, for a relocalization or a question), the ranking is evidence too: a
  // frame's own key images come first far more often than chance puts a wrong one there, and a comparison says less
  // once its rank is known (the two measure the same likeness). By the rank's bucket (kRankBuckets): `rank_alone`, the
  // log ratio of a key image ranked there (every key image of the route, compared or not); a matched comparison of it
  // then weighs ranked_intercept + ranked_per_significance * s + ranked_per_link_share * share + rank_given[bucket]
  // minus rank_alone[bucket] (its rank is weighed already); an unmatched one `unmatched`. Empty: the ranking is not
  // weighed (binary descriptors: not fitted).
  std::vector<double> rank_alone;
  std::vector<double> rank_given;
  double ranked_intercept = 0.0;
  double ranked_per_significance = 0.0;
  double ranked_per_link_share = 0.0;

  // A comparison accepted because its heading mode stands out against the frame's rivals (Localizer::HeadingStandsOut)
  // weighs at least this: chance refused it, so the model above weighs it as a weak or negative likeness, though the
  // rule accepted no wrong key image of michigan_seasons' 2,640 and none more than two places off on
  // corridor_conditions (docs/measurements/localization-conditions.md, "A heading that stands out"). 0: not weighed so.
  double heading_stands_out = 0.0;
};

// The buckets of ranks the model weighs: [0], [1, 2], [3, 4], [5, 9], [10, ...) (the relocalization compares the 5
// best, --candidates). Returns the bucket of 0-based rank `rank`.
int RankBucket(int rank);

// The fitted models: for binary descriptors (ORB) and for the others (XFeat, ALIKED, LoFTR).
EvidenceModel BinaryDescriptorEvidence();
EvidenceModel FloatDescriptorEvidence();

// `link_verified`: the verified matches of the key image's link with its route neighbour (the smaller of two; 0
// when it has none, and then the share counts as 0). `rank`: the key image's 0-based rank when the frame was ranked
// and the model weighs the ranking (then what the comparison adds to RankLogRatio), -1 otherwise.
double EvidenceLogRatio(const EvidenceModel& model, const KeyComparison& comparison, int link_verified, int rank = -1);
// The log ratio of a key image ranked `rank` (0-based) among the route's key images; 0 when the model has none.
double RankLogRatio(const EvidenceModel& model, int rank);

}  // namespace vmap
