#pragma once
// The tracker's pace over a run's first frames (LocalizerOptions::lagging_tracker_frames, lagging_start_frames): where
// it was after each of the last few, so that a tracker that barely moved on at the run's start can be asked whether
// the route further on verifies the frame (Localizer::LookFurtherWhenLagging, localizer_lagging_tracker.cc).

#include <deque>

namespace vmap {

class LaggingStart {
 public:
  // `frames`: lagging_tracker_frames (0: never lags); `start_frames`: lagging_start_frames.
  LaggingStart(int frames, int start_frames) : frames_(frames), start_frames_(start_frames) {}

  // Up to start_frames frames after the run's first, the tracker moved on by at most one key image over the last
  // `frames` frames (a move back is the rules' of a step back, not a lag).
  bool Lags() const;
  // After the frame's result is final: the tracker at route `position` (-1: no estimate, which forgets the pace).
  void Remember(int position);
  void Reset();

 private:
  int frames_;
  int start_frames_;
  int frames_since_start_ = 0;  // counted only as far as Lags reads it: a long run does not overflow the count
  std::deque<int> recent_positions_;
};

}  // namespace vmap
