// A frame nothing verifies, placed where its weak evidence agrees: the relocalization's ranking and the heading modes
// of its comparisons, each too weak for chance alone, naming the same key image (Localizer::Track's step-on rules,
// LocalizerOptions::step_on_where_evidence_agrees and step_on_after_lost_frames).
#include <algorithm>
#include <limits>

#include "vmap/localization/localizer.h"

namespace vmap {

bool Localizer::EvidenceAgreesOnNext(int position) const {
  // Measured with binary descriptors only (across seasons ORB's chance refuses most right key images; XFeat's rarely).
  const int next = position + 1;
  return heading_accepts_ && next < static_cast<int>(route_.size()) && RankingFirst() == next && HeadingMode() == next;
}

int Localizer::RankingFirst() const {
  // The ranking holds the route's key images in route order: ranked_[r].key is a route position.
  if (ranked_.size() < 2 || ranked_[0].score <= ranked_[1].score) return -1;
  return ranked_[0].key;
}

int Localizer::HeadingMode() const {
  int mode = -1, mode_votes = -1, rival_votes = -1;
  for (const Memo& m : comparisons_) {
    const int position = route_position_of_key_[m.comparison.key];
    if (position < 0) continue;
    const int votes = m.comparison.heading.votes;
    if (position == mode) {
      mode_votes = std::max(mode_votes, votes);
    } else if (votes > mode_votes) {
      rival_votes = std::max(rival_votes, mode_votes);
      mode = position;
      mode_votes = votes;
    } else {
      rival_votes = std::max(rival_votes, votes);
    }
  }
  return mode_votes > rival_votes ? mode : -1;
}

LocalizationResult Localizer::PlacedByAgreement(LocalizationResult placed) {
  // Placed, but not steered by (guidance "none"): the place is the two measures' agreement, the heading that of
  // comparisons chance and the heading rule refused. On michigan_seasons 13 of the 37 frames placed so had a heading
  // against their key image more than 35 px off the hand label, against 25 of the 336 frames placed otherwise.
  // heading_key_px stays, as a lost frame's does: what the comparison measured, not to steer by.
  placed.heading_px = placed.heading_deg = std::numeric_limits<double>::quiet_NaN();
  placed.translation_known = false;
  return placed;
}

}  // namespace vmap
