// A tracker lagging the run's start looks further ahead (LocalizerOptions::lagging_tracker_frames,
// lagging_start_frames). Why: a run's first place rests on a frame or two of evidence, and the start key image's prior
// holds the belief behind it, so a robot further on than --start-key says may be placed short, at a key image that
// looks like the place further on; the tracker then compares only that key image and the ones just
// after it, the look-alike keeps verifying, and the robot moves away from where the frames are steered by. A tracker
// that has not moved on two key images in several of the run's first frames is asked whether the route further on
// verifies the frame clearly.
#include <algorithm>

#include "vmap/localization/localizer.h"

namespace vmap {

namespace {

// The key images compared past the next one: the next one was compared by the lookahead, and a place two key images
// short (corridor_conditions' start from repeat frame 20) is mended by the second after it.
constexpr int kFurther = 2;

}  // namespace

void Localizer::LookFurtherWhenLagging(const Frame& frame, const ImageFeatures& features, KeyComparison& best,
                                       int& best_position) {
  const int frames = options_.lagging_tracker_frames;
  if (frames <= 0 || binary_descriptors_ || !best.accepted || frames_since_start_ > options_.lagging_start_frames ||
      static_cast<int>(recent_positions_.size()) < frames || PassesChance(best, options_.look_past_max_log10_nfa)) {
    return;
  }
  // Lagging: the tracker is no more than one key image further on than `frames` frames ago (a move back is the rules'
  // of a step back).
  const int moved = recent_positions_.back() - recent_positions_.front();
  if (moved < 0 || moved >= 2) return;
  StepOnWhereClearlyBetter(frame, features, best_position + 2, best_position + 1 + kFurther,
                           options_.lagging_step_weighs_belief, best, best_position);
}

void Localizer::RememberPace() {
  // Counted only as far as the rule reads it: a long run does not overflow the count.
  if (frames_since_start_ <= options_.lagging_start_frames) ++frames_since_start_;
  if (position_ < 0) {
    recent_positions_.clear();
    return;
  }
  recent_positions_.push_back(position_);
  while (static_cast<int>(recent_positions_.size()) > std::max(1, options_.lagging_tracker_frames)) {
    recent_positions_.pop_front();
  }
}

}  // namespace vmap
