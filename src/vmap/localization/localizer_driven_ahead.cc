// A tracker behind the distance driven looks where the odometry says (LocalizerOptions::driven_past_positions). Why:
// the tracker compares only its key image and the ones just after it, and where one of them looks like the place the
// robot has reached, it keeps verifying while the robot drives on; the belief, moved by the distance driven, is held
// back by that evidence alone, since nothing is compared where the robot is. The teach run's odometry at each key
// image says where on the route the distance driven since the tracker reached its key image puts the robot.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include "vmap/localization/localizer.h"

namespace vmap {

int Localizer::NearestRoutePosition(double teach_metres) const {
  int nearest = -1;
  double nearest_gap = std::numeric_limits<double>::infinity();
  for (int q = 0; q < static_cast<int>(route_teach_metres_.size()); ++q) {
    const double gap = std::abs(route_teach_metres_[q] - teach_metres);  // NaN (not covered) never nearer
    if (gap < nearest_gap) {
      nearest_gap = gap;
      nearest = q;
    }
  }
  return nearest;
}

std::optional<double> Localizer::TeachMetresDriven() const {
  const std::optional<double> metres = pace_.metres_driven();
  if (!metres || !driven_from_ || driven_from_->stretch != pace_.driving_stretch()) return std::nullopt;
  return driven_from_->teach_metres + route_teach_direction_ * (*metres - driven_from_->metres);
}

void Localizer::LookWhereDriven(const Frame& frame, const ImageFeatures& features, KeyComparison& best,
                                int& best_position) {
  const int past = options_.driven_past_positions;
  if (past <= 0 || !best.accepted) return;
  const std::optional<double> teach_metres = TeachMetresDriven();
  if (!teach_metres) return;
  const int driven = NearestRoutePosition(*teach_metres);
  if (driven < 0 || driven - best_position < past) return;
  // The key image after the tracked one was compared by the lookahead. The belief is weighed where the tracker steps
  // to, as a lagging tracker's step weighs it: the look-alike's evidence holds it where the tracker was.
  StepOnWhereClearlyBetter(frame, features, std::max(best_position + 2, driven - 1), driven + 1, true, best,
                           best_position);
}

void Localizer::RememberWhereDriven(int position_before) {
  const std::optional<double> metres = pace_.metres_driven();
  const int size = static_cast<int>(route_teach_metres_.size());
  if (position_ < 0 || position_ >= size || !metres || !std::isfinite(route_teach_metres_[position_])) {
    driven_from_.reset();
    return;
  }
  const double at_key = route_teach_metres_[position_];
  const std::optional<double> driven = TeachMetresDriven();
  // A stretch of odometry begins, or the tracker was relocalized (more than kNear either way): counted from its key
  // image.
  if (!driven || std::abs(position_ - position_before) > kNear) {
    driven_from_ = DrivenFrom{at_key, *metres, pace_.driving_stretch()};
    return;
  }
  // The tracker stepped on to within a route position of where the distance puts the robot, or past it: the robot
  // is taken to be on the tracker's segment, where the distance puts it if that is on the segment. A tracker that
  // stayed, or stepped on behind, leaves the count as it was: the robot drives on.
  const bool moved = position_ != position_before;
  if (!moved || position_ < NearestRoutePosition(*driven) - 1) return;
  const double segment_end = position_ + 1 < size && std::isfinite(route_teach_metres_[position_ + 1])
                                 ? route_teach_metres_[position_ + 1]
                                 : at_key;
  const double low = std::min(at_key, segment_end), high = std::max(at_key, segment_end);
  driven_from_ = DrivenFrom{std::clamp(*driven, low, high), *metres, pace_.driving_stretch()};
}

}  // namespace vmap
