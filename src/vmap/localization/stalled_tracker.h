#pragma once
// The count of a tracker held at one key image while the next one sees nothing of the frames
// (LocalizerOptions::stalled_tracker_frames): the frames in a row it was held so, and the bar at which the hold is
// questioned. The Localizer judges each frame (Localizer::HeldWhereNextSeesNothing) and asks the question
// (localizer_stalled_tracker.cc); this keeps the count between frames.

namespace vmap {

class StalledTracker {
 public:
  // `frames`: stalled_tracker_frames; `unsettled_frames`: unsettled_stalled_tracker_frames, the bar where the hold
  // began within two frames of a frame not steered by (0: as `frames`).
  StalledTracker(int frames, int unsettled_frames) : frames_(frames), unsettled_frames_(unsettled_frames) { Reset(); }

  // A frame held at route `position` reaches the bar: with it the tracker has been held there bar frames in a row.
  bool Due(int position) const { return position == position_ && held_frames_ + 1 >= bar_; }
  // The frame being localized was questioned (Localizer::QuestionStalledTracker); it stands still where held.
  void MarkQuestioned() { questioned_ = true; }
  bool questioned() const { return questioned_; }
  void set_held_still(bool still) { held_still_ = still; }
  bool held_still() const { return held_still_; }

  // After the frame's result is final: the frame at route `position`, placed (tracking or relocalized) or not, held
  // where the next key image sees nothing or not; `tracker` the route position the tracker is left at;
  // `placed_in_a_row` the frames placed in a row before this one. Ends the frame (questioned and held_still reset).
  void Count(int position, bool placed, bool held, int tracker, int placed_in_a_row);
  void Reset();

 private:
  int frames_;
  int unsettled_frames_;
  int position_ = -1;    // the route position the tracker was held at; -1: not held
  int held_frames_ = 0;  // the frames in a row it was held there
  int bar_ = 0;          // the hold at position_ is questioned at this many frames
  bool questioned_ = false;
  bool held_still_ = false;
};

}  // namespace vmap
