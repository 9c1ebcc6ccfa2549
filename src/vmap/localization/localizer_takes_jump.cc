// A far place needs two frames (Localizer::TakesJump): across lighting one frame's chance match looks like a place.
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

bool Localizer::TakesJump(int from, int to, int lost_frames) {
  if (options_.belief.window <= 0 || options_.belief.min_confidence <= 0.0 ||
      std::abs(to - from) <= JumpReach(lost_frames)) {
    return true;
  }
  if (pointed_before_ >= 0 && std::abs(to - pointed_before_) <= kNear) {
    // Two frames in a row point there; the belief, weighed by both, must not hold less near it than near `from`.
    WeighComparisons();
    if (NearDensity(to) >= NearDensity(from)) return true;
  }
  pointed_ = to;
  return false;
}

}  // namespace vmap
