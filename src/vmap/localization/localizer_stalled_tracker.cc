// A tracker held at one key image while the next one sees nothing of the frames is questioned
// (LocalizerOptions::stalled_tracker_frames). Why: the tracker compares only its key image and the next, and a key
// image that verifies with every frame (a camera that sees its own lens rim matches itself everywhere) keeps accepting
// frames the robot took far from it; the frames' evidence never reaches the belief from elsewhere, and nothing
// questions a belief it alone weighs. A robot moving on sees its next key image within a few frames; one held longer is
// asked where it is over the whole route, as a relocalization would ask.
#include <algorithm>
#include <cstdlib>
#include <utility>

#include "vmap/localization/localizer.h"

namespace vmap {

bool Localizer::HeldWhereNextSeesNothing(const LocalizationResult& result) const {
  const int position = result.route_position;
  if (options_.stalled_tracker_frames <= 0 || binary_descriptors_ || !IsPlaced(result.status) || position < 0 ||
      result.next_key < 0) {
    return false;
  }
  return !result.to_next.matched || !(result.to_next.log10_nfa <= kWithinLittleChance);
}

void Localizer::QuestionStalledTracker(const LocalizationResult& result, const Frame& frame,
                                       const ImageFeatures& features) {
  // A robot that stopped shows the same place on every frame: the hold is the stop's, and the frame's evidence (its
  // ranking the same each frame) would be weighed again as if new.
  held_still_ = HeldWhereNextSeesNothing(result) && StillSinceFrameBefore(features);
  if (held_still_ || !HeldWhereNextSeesNothing(result) || result.route_position != stalled_position_ ||
      stalled_frames_ + 1 < stall_bar_) {
    return;
  }
  CompareBestRanked(frame, features);
  stall_questioned_ = true;
}

void Localizer::DoubtStalledTracker(LocalizationResult& result) const {
  if (!stall_questioned_ || !IsPlaced(result.status)) return;
  const int first = RankingFirst();
  if (first < 0 || std::abs(first - result.route_position) > kNear) result.status = LocalizationStatus::kUncertain;
}

void Localizer::CountStall(const LocalizationResult& result) {
  const bool questioned = std::exchange(stall_questioned_, false);
  // A still frame neither adds to the hold nor ends it.
  if (std::exchange(held_still_, false) && result.route_position == stalled_position_) return;
  // A frame the question withheld leaves the tracker where it was held: the frames after it are questioned too.
  if (questioned && !IsPlaced(result.status) && position_ == stalled_position_) {
    ++stalled_frames_;
    return;
  }
  if (!HeldWhereNextSeesNothing(result)) {
    stalled_position_ = -1;
    stalled_frames_ = 0;
    return;
  }
  if (result.route_position != stalled_position_) {
    stalled_frames_ = 0;
    // Frames placed in a row before this one: at most one, and a frame within two of this one was not steered by.
    const bool unsettled = placed_in_a_row_ <= 1 && options_.unsettled_stalled_tracker_frames > 0;
    stall_bar_ = unsettled ? std::min(options_.unsettled_stalled_tracker_frames, options_.stalled_tracker_frames)
                           : options_.stalled_tracker_frames;
  }
  ++stalled_frames_;
  stalled_position_ = result.route_position;
}

}  // namespace vmap
