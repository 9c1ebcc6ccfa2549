// A tracker held by little beyond chance looks past a next key image that verifies by little beyond chance too
// (LocalizerOptions::look_past_weak_next): it steps on to the key image past it where that one verifies more, clearly
// (LocalizerOptions::look_past_max_log10_nfa).
#include <algorithm>

#include "vmap/localization/localizer.h"

namespace vmap {

void Localizer::LookPastWeakNext(const Frame& frame, const ImageFeatures& features, int position, KeyComparison& best,
                                 int& best_position) {
  const int next = best_position + 1, past = best_position + 2;
  // Asked only where the lookahead stopped at `next` (it compared it, and it did not beat `best`) and `best` holds the
  // frame by little beyond chance.
  if (!options_.look_past_weak_next || binary_descriptors_ || !best.accepted ||
      PassesChance(best, kBeyondLittleChance) || next > position + lookahead_ ||
      past >= static_cast<int>(route_.size())) {
    return;
  }
  // Why: across lighting XFeat verifies 15-25 matches at every key image near the frame, and a next key image that
  // sees little of the frame (corridor_conditions' key image 5, teach frame 23: 15-22 matches at log10 NFA -8 to 0 on
  // 16 of 18 repeat frames 25-30) stops the lookahead while the key image past it verifies clearly (key image 6, teach
  // frame 25: 25-29 at -15 to -17 on frames 26-27). The tracker stayed at key image 3 or 4 (teach frames 9 and 13, the
  // look-alikes of repeat frames 20-34) and repeat frame 30 was steered by there, 3 key images behind the right 7-8
  // (the verifier's seeds 8, 9 and 14; docs/measurements/localization-conditions.md, "A tracker held at a look-alike
  // looks past a weak next key image"). The route goes forwards: a tracker held behind falls further behind.
  if (PassesChance(comparisons_.Once(features, route_[next]), kBeyondLittleChance)) return;
  const KeyComparison beyond = CompareTracked(frame, features, past);
  // Stepped on to only where it verifies clearly (look_past_max_log10_nfa): at corridor_conditions' repeat frames 90-94
  // key image 31 (teach frame 101) verifies 22-28 matches at -10.2 to -11.5 past the weak key image 30, and the tracker
  // at 28-29 (right) stepped on a key image early; the key image past that mends a held tracker verifies at -15 to -17.
  if (!ClearlyBeats(beyond, best)) return;
  best = beyond;
  best_position = past;
}

bool Localizer::ClearlyBeats(const KeyComparison& further, const KeyComparison& tracked) const {
  return PassesChance(further, options_.look_past_max_log10_nfa) && further.num_verified > tracked.num_verified &&
         IsBetterMatch(further, tracked);
}

bool Localizer::StepOnWhereClearlyBetter(const Frame& frame, const ImageFeatures& features, int first, int last,
                                         bool weigh_belief, KeyComparison& best, int& best_position) {
  KeyComparison found;
  int found_position = -1;
  for (int q = first; q <= std::min(last, static_cast<int>(route_.size()) - 1); ++q) {
    const KeyComparison there = CompareTracked(frame, features, q);
    if (ClearlyBeats(there, best) && (found_position < 0 || IsBetterMatch(there, found))) {
      found = there;
      found_position = q;
    }
  }
  if (found_position < 0) return false;
  best = found;
  best_position = found_position;
  // The step is the tracker's move, which the frame's comparisons, weighed as any, do not tell the belief: the
  // evidence of the key image stepped from still holds it there (lagging_step_weighs_belief).
  if (weigh_belief) {
    WeighBeliefs(found_position, kAgreementLogRatio);
    NormalizeBeliefs();
  }
  return true;
}

}  // namespace vmap
