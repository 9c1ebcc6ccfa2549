#pragma once
// The continuity of the heading (GuidedMatchingOptions: continuity_share, window_matching): from one frame to the next
// a robot's heading against a key image changes little, so the previous frame's heading against it predicts how the
// frame's matches with it move. A guided comparison chance refuses is accepted when enough of its matches move so, and
// matching within a window around the prediction looks where they should be. This holds the previous frame's headings
// and the tests on them.

#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/features/matcher.h"
#include "vmap/localization/frame_comparisons.h"
#include "vmap/localization/key_comparison.h"
#include "vmap/localization/localizer_guided_options.h"

namespace vmap {

class HeadingContinuity {
 public:
  explicit HeadingContinuity(const GuidedMatchingOptions& options) : options_(options) {}

  // The previous frame's heading (px) against key image `key`; none when that frame was not compared with it.
  std::optional<double> Predicted(int key) const;
  // The previous frame's headings are a guess's (Remember): the continuity does not hold the frame to them.
  bool follows_a_guess() const { return follows_a_guess_; }
  // `guided`, the guided matches of the frame with a key image whose first comparison is `first`, move by
  // `predicted_dx` (at least continuity_share of them, within the window of bench/evidence_dump's near_L), and `first`
  // passes the guards. `size`: the frame's.
  bool Holds(const KeyComparison& first, const TentativeMatches& guided, double predicted_dx, cv::Size size) const;
  // The first comparison's heading mode and log10 NFA are within the guards (continuity_heading_confidence,
  // continuity_max_log10_nfa).
  bool PassesGuards(const KeyComparison& first) const;

  // After a frame: its headings against the key images it was compared with predict the next frame's; `guess`: the
  // frame was a guess (uncertain, and moved the estimate more than kNear), which the next frame is not held to.
  void Remember(const FrameComparisons& comparisons, bool guess);
  void Reset();

 private:
  GuidedMatchingOptions options_;
  std::vector<std::pair<int, double>> previous_headings_;  // (key, heading px), those with one
  bool follows_a_guess_ = false;
};

}  // namespace vmap
