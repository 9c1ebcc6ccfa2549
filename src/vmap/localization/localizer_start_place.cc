// A run started elsewhere than the start key image says confirms its place only where that place stands out of a far
// one (LocalizerOptions::start_place_stands_out). Why: across lighting XFeat verifies as much at a look-alike stretch
// of the route as at the right key images, and before the start is confirmed no run of frames steered by holds the
// tracker. corridor_conditions from repeat frame 50 at the verifier's seed 10: frame 54 verified key image 16 (right)
// with 22 matches and key images 29-30 with 21-22, was relocalized at 29 and confirmed the start there, 14 key images
// off (docs/measurements/localization-conditions.md, "A run started elsewhere confirms a place that stands out").
#include <algorithm>
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

bool Localizer::StartPlaceTiesFar(const LocalizationResult& result, const Frame& frame, const ImageFeatures& features) {
  const int position = result.route_position;
  if (!options_.start_place_stands_out || !start_unconfirmed_ || binary_descriptors_ ||
      options_.belief.min_confidence <= 0.0 || position < 0) {
    return false;
  }
  // Where the place and its neighbours hold more than half the route (michigan_seasons' routes of 5 places), near and
  // far are not told apart, as in EvidenceWeighsAgainst.
  if (2 * NearWidth(position) > static_cast<int>(route_.size())) return false;
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
  if (verified < 0) return false;
  auto ties = [&](const KeyComparison& c) {
    return c.accepted &&
           (c.num_verified >= verified || EvidenceLogRatio(evidence_, c, link_verified_[c.key]) >= weight);
  };
  auto far = [&](int q) { return q >= 0 && std::abs(q - position) > kNear; };
  for (const Memo& m : comparisons_) {
    if (far(route_position_of_key_[m.comparison.key]) && ties(m.comparison)) return true;
  }
  // The likeliest far place, as the frame's descriptors tell, when the frame did not compare it: compared now, without
  // weighing the belief (nor the frame's ranking, when the frame was not ranked): the frames' evidence is what the
  // belief weighed; this only asks whether the frame can tell its place from a far one.
  const std::vector<RankedKey> ranked = ranked_.empty() ? RouteRanking(frame, features) : ranked_;
  for (const RankedKey& r : ranked) {  // route positions, best first
    if (!far(r.key)) continue;
    const int key = route_[r.key];
    for (const Memo& m : comparisons_) {
      if (m.comparison.key == key) return false;  // compared above
    }
    return ties(Compare(features, key));
  }
  return false;
}

}  // namespace vmap
