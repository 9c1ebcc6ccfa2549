#include "vmap/localization/stalled_tracker.h"

#include <algorithm>
#include <utility>

namespace vmap {

void StalledTracker::Count(int position, bool placed, bool held, int tracker, int placed_in_a_row) {
  const bool questioned = std::exchange(questioned_, false);
  // A still frame neither adds to the hold nor ends it.
  if (std::exchange(held_still_, false) && position == position_) return;
  // A frame the question withheld leaves the tracker where it was held: the frames after it are questioned too.
  if (questioned && !placed && tracker == position_) {
    ++held_frames_;
    return;
  }
  if (!held) {
    position_ = -1;
    held_frames_ = 0;
    return;
  }
  if (position != position_) {
    held_frames_ = 0;
    // Frames placed in a row before this one: at most one, and a frame within two of this one was not steered by.
    const bool unsettled = placed_in_a_row <= 1 && unsettled_frames_ > 0;
    bar_ = unsettled ? std::min(unsettled_frames_, frames_) : frames_;
  }
  ++held_frames_;
  position_ = position;
}

void StalledTracker::Reset() {
  position_ = -1;
  held_frames_ = 0;
  bar_ = frames_;
  questioned_ = held_still_ = false;
}

}  // namespace vmap
