// The tracker at the key image before the route's last steps on to the last one by chance, not by the count
// (LocalizerOptions::step_on_to_last_by_chance).
#include "vmap/localization/localizer.h"

namespace vmap {

std::optional<bool> Localizer::StepsOnToLastKeyImage(const KeyComparison& ahead, const KeyComparison& tracked,
                                                     int ahead_position) const {
  const int last = static_cast<int>(route_.size()) - 1;
  if (!options_.step_on_to_last_by_chance || binary_descriptors_ || !tracked.accepted || ahead_position != last ||
      position_ != last - 1) {
    return std::nullopt;
  }
  // Why: nothing lies past the route's last key image, and the count misleads on both sides of it. On
  // corridor_conditions' last segment (key images 31 and 32, teach frames 101 and 108) XFeat verifies more matches with
  // 31 than with 32 on repeat frames 108-110 (frame 110: 22-25 against 15-23), where only 32 is right for frame 110,
  // while 32 verifies as many or a few fewer at a log10 NFA lower by 4-12 on frame 108; and on frames 97-99 (right:
  // 29-31) 32 verifies a few more than 31 at a higher log10 NFA (seeds 4 and 13, frame 97: 27 at -15.1 against 24 at
  // -17.9, 29 at -13.2 against 26 at -17.0), and the lookahead stepped on to it a key image early. By the count, frame
  // 110 was steered by at 31 at 15 of the verifier's seeds 0-31, frames 97-99 at 32 23 times
  // (docs/measurements/localization-conditions.md, "The route's last key image is stepped on to by chance").
  // Stepped on to where it verifies at a log10 NFA lower than the tracked key image's by
  // step_on_to_last_log10_nfa_lead, whatever the count: a lead of 4-5 would take repeat frame 97 at seed 8 (28 matches
  // at -17.9 against 31's 28 at -12.9), a key image early.
  return ahead.accepted && ahead.log10_nfa <= tracked.log10_nfa - options_.step_on_to_last_log10_nfa_lead;
}

}  // namespace vmap
