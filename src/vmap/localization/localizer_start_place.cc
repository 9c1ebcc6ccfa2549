// A run started elsewhere than the start key image says confirms its place only where that place stands out of a far
// one (LocalizerOptions::start_place_stands_out). Why: across lighting XFeat verifies as much at a look-alike stretch
// of the route as at the right key images, and before the start is confirmed no run of frames steered by holds the
// tracker. corridor_conditions from repeat frame 50 at the verifier's seed 10: frame 54 verified key image 16 (right)
// with 22 matches and key images 29-30 with 21-22, was relocalized at 29 and confirmed the start there, 14 key images
// off (docs/measurements/localization-conditions.md, "A run started elsewhere confirms a place that stands out").
// The frames' evidence alone holds a frame the tracker placed without ranking it only where the tracker compared it
// (LocalizerOptions::start_evidence_ranks_frame): its ranking weighs that belief too. The corridor from repeat frame 90
// at the verifier's seed 12: frames 91-92 were moved to key image 12-13 (right 28-30), frame 92 tracked there verified
// key image 13 with 24 matches and 29, compared for the question alone, with 23; its comparisons at 12-14 swung the
// frames' evidence from 28 to 12, which confirmed the start there, 15 key images off ("A start confirmed at a
// look-alike is asked by the frame's ranking").
// The far key image compared for the question alone weighs both beliefs once the frame is decided
// (LocalizerOptions::start_question_weighs): unweighed, a tracker held at a look-alike kept the right place out of the
// belief, the frames uncertain at the look-alike until a relocalization found it ("The start's question weighs the
// belief").
#include <algorithm>
#include <cstdlib>
#include <optional>
#include <utility>
#include <vector>

#include "vmap/localization/localizer.h"

namespace vmap {

std::optional<std::vector<RankedKey>> Localizer::RankForUnconfirmedStart(const LocalizationResult& result,
                                                                         const Frame& frame,
                                                                         const ImageFeatures& features) {
  const int position = result.route_position;
  if (!(options_.start_place_stands_out || options_.start_evidence_ranks_frame) || !start_unconfirmed_ ||
      binary_descriptors_ || options_.belief.min_confidence <= 0.0 || position < 0) {
    return std::nullopt;
  }
  // Where the place and its neighbours hold more than half the route (michigan_seasons' routes of 5 places), near and
  // far are not told apart, as in EvidenceWeighsAgainst.
  if (!TellsNearFromFar(position)) return std::nullopt;
  if (!(result.to_key.accepted && result.to_key.key >= 0) && !(result.to_next.accepted && result.to_next.key >= 0)) {
    return std::nullopt;  // nothing accepted at the place: nothing to tell from a far one
  }
  if (!ranked_.empty()) return ranked_;
  std::vector<RankedKey> ranked = RouteRanking(frame, features);
  if (options_.start_evidence_ranks_frame) WeighEvidenceByRanking(ranked);
  return ranked;
}

bool Localizer::StartPlaceTiesFar(const LocalizationResult& result, const ImageFeatures& features,
                                  const std::vector<RankedKey>& ranked) {
  if (!options_.start_place_stands_out) return false;
  const int position = result.route_position;
  // What the frame holds at its place: the most verified matches and the most evidence (the comparison alone, as the
  // evidence model weighs it) of its accepted key images.
  int verified = -1;
  double weight = 0.0;
  for (const KeyComparison* c : {&result.to_key, &result.to_next}) {
    if (!c->accepted || c->key < 0) continue;
    const double w = EvidenceLogRatio(evidence_, *c, link_verified_[c->key]);
    weight = verified < 0 ? w : std::max(weight, w);
    verified = std::max(verified, c->num_verified);
  }
  auto ties = [&](const KeyComparison& c) {
    return c.accepted &&
           (c.num_verified >= verified || EvidenceLogRatio(evidence_, c, link_verified_[c.key]) >= weight);
  };
  auto far = [&](int q) { return q >= 0 && std::abs(q - position) > kNear; };
  for (const Memo& m : comparisons_) {
    if (far(route_position_of_key_[m.comparison.key]) && ties(m.comparison)) return true;
  }
  // The likeliest far place, as the frame's descriptors tell, when the frame did not compare it: compared now. It asks
  // whether the frame can tell its place from a far one; the beliefs weigh it only once the frame is decided
  // (WeighStartQuestion), so that the frame's own decisions are as the frames' evidence before it made them.
  for (const RankedKey& r : ranked) {  // route positions, best first
    if (!far(r.key)) continue;
    const int key = route_[r.key];
    for (const Memo& m : comparisons_) {
      if (m.comparison.key == key) return false;  // compared above
    }
    KeyComparison question = Compare(features, key);
    const bool tie = ties(question);
    if (options_.start_question_weighs) start_question_ = std::move(question);
    return tie;
  }
  return false;
}

void Localizer::WeighStartQuestion() {
  if (!start_question_) return;
  const KeyComparison question = *std::exchange(start_question_, std::nullopt);
  const int position = route_position_of_key_[question.key];
  if (position < 0) return;
  // As WeighComparisons weighs a comparison of the frame: given the frame's ranking where it was ranked.
  const int bucket = bucket_of_position_.empty() ? -1 : bucket_of_position_[position];
  WeighBeliefs(position, EvidenceLogRatio(evidence_, question, link_verified_[question.key], bucket));
  NormalizeBeliefs();
}

void Localizer::WeighEvidenceByRanking(const std::vector<RankedKey>& ranked) {
  if (evidence_.rank_alone.empty()) return;
  // As WeighRanking weighs both beliefs for a ranked frame: every route position by its bucket, and the comparisons
  // weighed without the ranking by what their bucket changes.
  const std::vector<int> buckets = RankingBuckets(evidence_, ranked, static_cast<int>(route_.size()));
  for (size_t p = 0; p < route_.size(); ++p) {
    evidence_belief_.Weigh(static_cast<int>(p), RankLogRatio(evidence_, buckets[p]));
  }
  for (const Memo& m : comparisons_) {
    const int key = m.comparison.key;
    const int q = route_position_of_key_[key];
    if (q < 0 || !m.weighed || m.weighed_ranked) continue;
    evidence_belief_.Weigh(q, EvidenceLogRatio(evidence_, m.comparison, link_verified_[key], buckets[q]) -
                                  EvidenceLogRatio(evidence_, m.comparison, link_verified_[key]));
  }
  evidence_belief_.Normalize();
}

}  // namespace vmap
