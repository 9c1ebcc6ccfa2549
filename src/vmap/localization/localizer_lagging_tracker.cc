// A tracker lagging the run's start looks further ahead (LocalizerOptions::lagging_tracker_frames,
// lagging_start_frames). Why: a run's first place rests on a frame or two of evidence, and the start key image's prior
// holds the belief behind it, so a robot further on than --start-key says may be placed short, at a key image that
// looks like the place further on; the tracker then compares only that key image and the ones just
// after it, the look-alike keeps verifying, and the robot moves away from where the frames are steered by. A tracker
// that has not moved on two key images in several of the run's first frames is asked whether the route further on
// verifies the frame clearly.
#include "vmap/localization/localizer.h"

namespace vmap {

namespace {

// The key images compared past the next one: the next one was compared by the lookahead, and a place two key images
// short (corridor_conditions' start from repeat frame 20) is mended by the second after it.
constexpr int kFurther = 2;

}  // namespace

void Localizer::LookFurtherWhenLagging(const Frame& frame, const ImageFeatures& features, KeyComparison& best,
                                       int& best_position) {
  if (binary_descriptors_ || !best.accepted || !lagging_start_.Lags() ||
      PassesChance(best, options_.look_past_max_log10_nfa)) {
    return;
  }
  StepOnWhereClearlyBetter(frame, features, best_position + 2, best_position + 1 + kFurther,
                           options_.lagging_step_weighs_belief, best, best_position);
}

}  // namespace vmap
