// A tracker held at one key image while the next one sees nothing of the frames is questioned
// (LocalizerOptions::stalled_tracker_frames). Why: the tracker compares only its key image and the next, and a key
// image that verifies with every frame (a camera that sees its own lens rim matches itself everywhere) keeps accepting
// frames the robot took far from it; the frames' evidence never reaches the belief from elsewhere, and nothing
// questions a belief it alone weighs. A robot moving on sees its next key image within a few frames; one held longer is
// asked where it is over the whole route, as a relocalization would ask.
#include <cstdlib>

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
  const bool held = HeldWhereNextSeesNothing(result);
  // A robot that stopped shows the same place on every frame: the hold is the stop's, and the frame's evidence (its
  // ranking the same each frame) would be weighed again as if new.
  stall_.set_held_still(held && StillSinceFrameBefore(features));
  if (stall_.held_still() || !held || !stall_.Due(result.route_position)) return;
  CompareBestRanked(frame, features);
  stall_.MarkQuestioned();
}

void Localizer::DoubtStalledTracker(LocalizationResult& result) const {
  if (!stall_.questioned() || !IsPlaced(result.status)) return;
  const int first = RankingFirst();
  if (first < 0 || std::abs(first - result.route_position) > kNear) {
    result.status = LocalizationStatus::kUncertain;
    result.withheld_by = Withholding::kStalledTracker;
  }
}

}  // namespace vmap
