// A relocalization away from where the run was last steered by, on little beyond chance, is doubted
// (LocalizerOptions::doubt_relocalization_on_little_chance). Why: across lighting a far key image that looks like the
// frame verifies as many matches as the right ones, a little beyond chance. corridor_conditions' dark stretch at the
// verifier's seed 26: repeat frames 50-53 were uncertain, and frame 54 was relocalized at key image 30 (right: 14-15)
// on 21 matches at log10 NFA -3.1 (the next key image +0.5), steered by 16 key images from frame 48's key image 14
// (docs/measurements/localization-conditions.md, "A relocalization away on little chance is doubted"). A frame
// relocalized near the place steered by, or one whose key image verifies beyond a little chance, is not asked; nor
// one whose next key image does, where the belief singles the place out (away_next_key_min_confidence). A frame
// tracked that far is asked too: an uncertain frame moved the tracker there, a relocalization nothing steered by yet
// (the corridor from repeat frame 20 at the verifier's seed 48: frame 52 moved it to key image 31, right: 14-15, and
// frame 53 was tracked there on 24 matches at -8.2; "A frame tracked away on little chance is doubted").
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

bool Localizer::PlacedAwayOnLittleChance(const LocalizationResult& result) const {
  if (!options_.doubt_relocalization_on_little_chance || binary_descriptors_ || !IsPlaced(result.status) ||
      result.route_position < 0 || steered_before_ < 0 || std::abs(result.route_position - steered_before_) <= kNear) {
    return false;
  }
  // A frame the tracker followed from within kNear of that place, moving at most kNear on it, stepped on in the
  // route's order and was not put there by a guess: the corridor's dark stretch at the verifier's seeds 8 and 13, frame
  // 50 steered by at key image 13, uncertain frames 51-53, frames 54-55 tracked at 16 at log10 NFA -2.7 to -7.3 (55 is
  // right there, 54 a key image early) were doubted. A tracker that moved further on the frame is asked (the corridor
  // at seed 39: frame 21 tracked from key image 4 to 7, right: 4-5).
  if (result.status == LocalizationStatus::kTracking && frame_start_position_ >= 0 &&
      std::abs(frame_start_position_ - steered_before_) <= kNear &&
      std::abs(result.route_position - frame_start_position_) <= kNear) {
    return false;
  }
  auto beyond_little_chance = [](const KeyComparison& c) { return c.key >= 0 && PassesChance(c, kBeyondLittleChance); };
  if (beyond_little_chance(result.to_key)) return false;
  // The next key image vouches for the place only where the belief singles it out: corridor_conditions' dark frames
  // verify the route's end, key images 29-31, through the lens rim (seeds 87, 165 and 167: frame 55 at key image 29 at
  // log10 NFA -7.5 to -9.3, key image 30 at -15.4, the belief 0.55-0.74 near it; right: 14-16).
  const bool next_may_vouch = belief_.MassWithin(result.route_position, kNear) >= options_.away_next_key_min_confidence;
  return !(next_may_vouch && beyond_little_chance(result.to_next));
}

}  // namespace vmap
