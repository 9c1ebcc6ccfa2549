// A frame placed far behind the tracked estimate, and behind the place last steered by, where the key images near that
// estimate verify nearly as much (LocalizerOptions::doubt_jump_back, judge_jump_back_from_steered_place): doubted, not
// steered by, and the tracker stays.
#include <algorithm>
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

namespace {

// The key images near the tracked estimate verify at least this share of the matches of those the frame jumped back
// to: the jump is no clearer than the look-alike it may be (the share below which a key image is clearly the worse
// match, Localizer::Track's kClearlyWorse (localizer_track.cc)).
constexpr double kNotClearlyWorse = 0.7;
// ... counting only a key image near the estimate that verifies beyond a little chance (kBeyondLittleChance): the place
// a carried robot left, or one a run's wrong start put it at, still accepts a few chance matches across lighting (the
// kidnapped run at the verifier's seed 9, carried back from repeat frame 110 to 22: 23 at log10 NFA -6.3 near where it
// was, 27 at -15.0 where it is).

int AcceptedVerified(const KeyComparison& comparison) { return comparison.accepted ? comparison.num_verified : 0; }

}  // namespace

void Localizer::DoubtJumpBack(LocalizationResult& result) {
  const int from = frame_start_position_, to = result.route_position;
  if (!options_.doubt_jump_back || binary_descriptors_ || !IsPlaced(result.status) || from < 0 || to < 0 ||
      to >= from - kNear) {
    return;
  }
  // Where the robot was last seen is the place last steered by; uncertain frames may have moved the tracker far ahead
  // of it (a far relocalization not taken), and a frame back near that place has not jumped back.
  if (options_.judge_jump_back_from_steered_place && steered_before_ >= 0 && to >= steered_before_ - kNear) return;
  const int jumped_to = std::max(AcceptedVerified(result.to_key), AcceptedVerified(result.to_next));
  // The most verified by an accepted key image within kNear of the estimate beyond a little chance, past the place.
  int near = 0;
  for (const Memo& m : comparisons_) {
    const int p = route_position_of_key_[m.comparison.key];
    if (p > to + 1 && std::abs(p - from) <= kNear && PassesChance(m.comparison, kBeyondLittleChance)) {
      near = std::max(near, m.comparison.num_verified);
    }
  }
  if (near == 0 || near < kNotClearlyWorse * jumped_to) return;
  result.status = LocalizationStatus::kUncertain;
  result.withheld_by = Withholding::kJumpBack;
  position_ = from;
  step_back_ruled_out_ = {};
}

}  // namespace vmap
