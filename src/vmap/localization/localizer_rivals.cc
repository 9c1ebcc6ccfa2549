// The acceptance of a frame against its own rivals (LocalizerOptions::min_rival_ratio): the map's links are of one
// season, and across seasons they refuse every key image a frame is compared with, the right one too. The key image
// that stands far above those compared elsewhere on the route is then accepted: it is the frame's place, not only
// its scene, as far as the frame itself can tell.
#include <algorithm>
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

int Localizer::AcceptAgainstRivals(const ImageFeatures& features) {
  if (options_.acceptance != AcceptanceRule::kChance || options_.min_rival_ratio <= 0.0) return -1;
  auto position_of = [&](const Memo& m) { return route_position_of_key_[m.comparison.key]; };
  int best = -1;  // index in comparisons_ (CompareOnce below may grow it)
  for (size_t i = 0; i < comparisons_.size(); ++i) {
    const Memo& m = comparisons_[i];
    if (!m.used || position_of(m) < 0) continue;
    if (m.comparison.accepted) return -1;  // the link share accepted one: nothing to decide here
    if (best < 0 || m.comparison.num_verified > comparisons_[best].comparison.num_verified) best = static_cast<int>(i);
  }
  if (best < 0) return -1;
  const KeyComparison& standout = comparisons_[best].comparison;
  if (!standout.matched || standout.log10_nfa > options_.rival_max_log10_nfa) return -1;
  const int position = position_of(comparisons_[best]);
  const int verified = standout.num_verified;
  // The rivals: key images more than kNear route positions away (nearer ones often see the frame too).
  int rival_verified = -1;
  for (const Memo& m : comparisons_) {
    const int q = position_of(m);
    if (m.used && q >= 0 && std::abs(q - position) > kNear)
      rival_verified = std::max(rival_verified, m.comparison.num_verified);
  }
  if (rival_verified < 0) {
    // None compared yet (the ranking put every candidate near it): the best-ranked key image far enough away.
    for (const RankedKey& r : ranked_) {
      if (std::abs(r.key - position) > kNear) {
        rival_verified = CompareOnce(features, route_[r.key]).num_verified;
        break;
      }
    }
    if (rival_verified < 0) return -1;  // a route too short to hold a rival: the frame cannot tell
  }
  if (verified < options_.min_rival_ratio * rival_verified) return -1;
  comparisons_[best].comparison.accepted = true;
  return position;
}

}  // namespace vmap
