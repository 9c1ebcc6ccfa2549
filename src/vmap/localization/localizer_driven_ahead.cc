// A tracker behind the distance driven looks where the odometry says (LocalizerOptions::driven_past_positions). Why:
// the tracker compares only its key image and the ones just after it, and where one of them looks like the place the
// robot has reached, it keeps verifying while the robot drives on; the belief, moved by the distance driven, is held
// back by that evidence alone, since nothing is compared where the robot is. The teach run's odometry at each key
// image says where on the route the distance driven since the tracker reached its key image puts the robot. Where it
// puts the robot at the tracked key image, the odometry also vouches for the tracker against a relocalization that
// one frame's near tie would take elsewhere.
#include <algorithm>
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

void Localizer::LookWhereDriven(const Frame& frame, const ImageFeatures& features, KeyComparison& best,
                                int& best_position) {
  const int past = options_.driven_past_positions;
  if (past <= 0 || !best.accepted) return;
  const int driven = pace_.DrivenPosition();
  if (driven < 0 || driven - best_position < past) return;
  // The key image after the tracked one was compared by the lookahead. The belief is weighed where the tracker steps
  // to, as a lagging tracker's step weighs it: the look-alike's evidence holds it where the tracker was.
  StepOnWhereClearlyBetter(frame, features, std::max(best_position + 2, driven - 1), driven + 1, true, best,
                           best_position);
}

bool Localizer::DrivenVouchesFor(int tracked, int elsewhere) const {
  if (options_.driven_past_positions <= 0) return false;
  const int driven = pace_.DrivenPosition();
  return driven >= 0 && std::abs(tracked - driven) <= 1 && std::abs(elsewhere - driven) > std::abs(tracked - driven);
}

void Localizer::RememberWhereDriven(int position_before) {
  const int driven = pace_.DrivenPosition();
  // A stretch of odometry begins, or the tracker was relocalized (more than kNear either way): counted from its key
  // image (forgotten where the tracker is lost or the teach odometry does not cover its key image).
  if (driven < 0 || std::abs(position_ - position_before) > kNear || !pace_.Covers(position_)) {
    pace_.CountDrivenFrom(position_);
    return;
  }
  // The tracker stepped on to within a route position of where the distance puts the robot, or past it: the robot
  // is taken to be on the tracker's segment, where the distance puts it if that is on the segment. A tracker that
  // stayed, or stepped on behind, leaves the count as it was: the robot drives on.
  const bool moved = position_ != position_before;
  if (moved && position_ >= driven - 1) pace_.PlaceDrivenOnSegment(position_);
}

}  // namespace vmap
