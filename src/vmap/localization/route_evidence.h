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
#include "vmap/localization/key_image_ranking.h"

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
  // once its ranking is known (the two measure the same likeness). By the key image's bucket in the ranking
  // (RankingBuckets): `rank_alone`, the log ratio of a key image in that bucket (every key image of the route, compared
  // or not); a matched comparison of it then weighs ranked_intercept + ranked_per_significance * s +
  // ranked_per_link_share * share + rank_given[bucket] minus rank_alone[bucket] (its bucket is weighed already); an
  // unmatched one `unmatched`. Empty: the ranking is not weighed.
  std::vector<double> rank_alone;
  std::vector<double> rank_given;
  double ranked_intercept = 0.0;
  double ranked_per_significance = 0.0;
  double ranked_per_link_share = 0.0;
  // The buckets: empty, by rank (RankBucket); else by how far a key image's votes stand out of the frame's,
  // (votes - median) / sqrt(median) (a count's noise grows as its square root), the bucket being how many of these
  // edges it reaches. ORB's votes by rank did not carry from the corridor's 46 key images to michigan's 5 (rank 3-4:
  // +1.24 against -0.95); by standout they do (docs/measurements/localization-conditions.md, "ORB's ranking by how its
  // votes stand out"). XFeat's by standout too: by rank, the first of a dark frame whose votes barely stand out weighed
  // as much as one far above the rest (docs/localize.md, "XFeat's ranking by how its votes stand out").
  std::vector<double> standout_edges;
  // The share of the joint model (the ranking and the comparisons given it) the belief weighs, the rest the comparisons
  // alone: a key image weighs rank_weight * rank_alone, a comparison rank_weight of what it adds to its bucket and
  // 1 - rank_weight of its model without the ranking, so that a compared key image weighs the same share of the joint
  // model as one not compared (halving rank_alone alone left a compared key image in the lowest bucket 0.55 above the
  // joint model: ORB's kidnapped run started at its frame 51 was steered by 14 key images off).
  double rank_weight = 1.0;
  // The frame's own ranking weighs the belief before the belief's rules move the tracker (Localizer::Believe). Off:
  // only after them, so that it may withhold the frame (uncertain) but moves nothing until the next frame's evidence
  // agrees with it; the frames after it are weighed by it as by any evidence.
  bool ranking_moves_own_frame = true;

  // A comparison accepted because its heading mode stands out against the frame's rivals (Localizer::HeadingStandsOut)
  // weighs at least this: chance refused it, so the model above weighs it as a weak or negative likeness, though the
  // rule accepted no wrong key image of michigan_seasons' 2,640 and none more than two places off on
  // corridor_conditions (docs/measurements/localization-conditions.md, "A heading that stands out"). 0: not weighed so.
  double heading_stands_out = 0.0;
};

// The buckets of ranks the model weighs by rank: [0], [1, 2], [3, 4], [5, 9], [10, ...) (the relocalization compares
// the 5 best, --candidates). Returns the bucket of 0-based rank `rank`.
int RankBucket(int rank);
// Each route position's bucket in the frame's ranking (`ranked`, best first, RankedKey::key a route position), by
// rank or by standout (EvidenceModel::standout_edges); -1 where the ranking says nothing: the model does not weigh
// it, or a frame whose median key image has no votes (a blank frame: its ranking orders ties and noise).
std::vector<int> RankingBuckets(const EvidenceModel& model, const std::vector<RankedKey>& ranked, int positions);

// The fitted models: for binary descriptors (ORB) and for the others (XFeat, ALIKED, LoFTR); both weigh the ranking by
// how far a key image's votes stand out. FloatDescriptorEvidenceByRank: the others' ranking by rank, as before
// (LocalizerOptions::rank_by_standout off).
EvidenceModel BinaryDescriptorEvidence();
EvidenceModel FloatDescriptorEvidence();
EvidenceModel FloatDescriptorEvidenceByRank();

// `link_verified`: the verified matches of the key image's link with its route neighbour (the smaller of two; 0
// when it has none, and then the share counts as 0). `bucket`: the key image's bucket in the frame's ranking
// (RankingBuckets) when the model weighs it (then what the comparison adds to RankLogRatio), -1 otherwise.
double EvidenceLogRatio(const EvidenceModel& model, const KeyComparison& comparison, int link_verified,
                        int bucket = -1);
// The log ratio of a key image in the ranking's `bucket` (rank_weight of rank_alone); 0 for -1 or when the model
// weighs no ranking.
double RankLogRatio(const EvidenceModel& model, int bucket);

// What a place named by more than one frame's comparisons tells of it (log of the likelihood ratio): ten to one. A lost
// frame's ranking and heading mode agreeing on a key image (michigan_seasons' ORB frames where nothing verifies: both
// name the right key image in 20.2 % of the frames, each wrong one in 2.0 %;
// docs/measurements/localization-conditions.md, "A lost frame steps on where its ranking and its heading agree"), and a
// lagging tracker's step further ahead (LocalizerOptions::lagging_step_weighs_belief) weigh the belief by it.
inline constexpr double kAgreementLogRatio = 2.302585092994046;  // ln 10

}  // namespace vmap
