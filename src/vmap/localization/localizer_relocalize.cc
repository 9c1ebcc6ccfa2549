// The Localizer without an estimate: the frame compared with the route's best-ranked key images, accepted by chance or
// against its rivals, and placed on the segment before or after the best of them; when nothing verifies, matched guided
// where the estimate was dropped.
#include <algorithm>
#include <cstdlib>
#include <vector>

#include "vmap/core/error.h"
#include "vmap/localization/localizer.h"
#include "vmap/localization/still_frame.h"

namespace vmap {

LocalizationResult Localizer::Reacquire(const Frame& frame, const ImageFeatures& features) {
  LocalizationResult found = Relocalize(frame, features);
  const int dropped = dropped_position_;
  if (dropped < 0 || found.status != LocalizationStatus::kLost) return found;
  // Nothing verified anywhere the ranking looked. The frames were lost where the tracker last held them, on evidence
  // too weak for chance: a frame's own guided comparison there may be accepted (a dark stretch of a corridor), though
  // the belief, weighed by those frames' weak evidence, no longer singles the place out.
  const int guided = TrackGuided(frame, features, dropped, /*whatever_the_belief=*/true);
  if (guided < 0) return found;
  LocalizationResult tracked;
  tracked.candidates = std::move(found.candidates);
  return TrackedAt(std::move(tracked), dropped, guided, features);
}

std::vector<int> Localizer::CompareBestRanked(const Frame& frame, const ImageFeatures& features) {
  RankRoute(frame, features);
  const int count = std::min<int>(options_.relocalization_candidates, static_cast<int>(ranked_.size()));
  std::vector<int> positions;
  std::vector<int> meanwhile;  // the first is compared at once; the helper starts from the last
  for (int i = count - 1; i > 0; --i) meanwhile.push_back(ranked_[i].key);
  CompareMeanwhile(features, meanwhile);
  for (int i = 0; i < count; ++i) {
    positions.push_back(ranked_[i].key);  // the ranking holds the route's key images in route order
    comparisons_.Once(features, route_[ranked_[i].key]);
  }
  return positions;
}

LocalizationResult Localizer::Relocalize(const Frame& frame, const ImageFeatures& features) {
  LocalizationResult result;
  const std::vector<int> positions = CompareBestRanked(frame, features);
  // Across seasons the link share refuses every key image: the frame's own rivals decide then.
  const int standout = AcceptAgainstRivals(frame, features);
  KeyComparison best;
  int best_position = -1;
  std::vector<KeyComparison> compared;
  for (size_t i = 0; i < positions.size(); ++i) {
    const int position = positions[i];
    compared.push_back(comparisons_.Once(features, route_[position]));
    const KeyComparison& c = compared.back();
    result.candidates.push_back(
        {route_[position], ranked_[i].score, c.accepted, c.similarity, c.num_verified, c.log10_nfa});
    if (IsBetterMatch(c, best)) {
      best = c;
      best_position = position;
    }
  }
  // Near the most verified candidate the likelier chance places the frame: across lighting a key image passed verifies
  // more of the scene than the one the frame is at.
  const int most_verified = best_position;
  for (size_t i = 0; most_verified >= 0 && i < positions.size(); ++i) {
    if (compared[i].accepted && std::abs(positions[i] - most_verified) <= options_.relocalization_likelier_reach &&
        !NoLikelierChance(best, compared[i])) {
      best = compared[i];
      best_position = positions[i];
    }
  }
  if (best_position < 0 && standout >= 0) {
    best_position = standout;
    best = comparisons_.Once(features, route_[standout]);
  }
  if (best_position < 0) {
    result.status = LocalizationStatus::kLost;
    return result;  // no estimate: key and next_key stay -1
  }
  // The frame is near the best key image: on the segment before it or after it. Each neighbour's verified
  // matches with the frame are weighed against those of its link with the best key image: a frame between the
  // neighbour and the key shares more with the neighbour than the key does, one beyond the key shares less. The
  // ratio makes segments of different lengths comparable (a raw count favours the shorter one).
  int position = best_position;
  // The segment before the key image only where the two share a scene: a frame is not between two unrelated places.
  if (position > 0 && scene_link_after_[position - 1]) {
    CompareMeanwhile(features, {position + 1});
    const KeyComparison before = comparisons_.Once(features, route_[position - 1]);
    const bool has_next = position + 1 < static_cast<int>(route_.size());
    const KeyComparison after = has_next ? comparisons_.Once(features, route_[position + 1]) : KeyComparison();
    if (before.accepted && (!has_next || !after.accepted)) {
      position -= 1;
    } else if (before.accepted) {
      const double before_share = SharedWithLink(before, route_[position - 1], route_[position]);
      const double after_share = SharedWithLink(after, route_[position], route_[position + 1]);
      if (before_share > 0 && after_share > 0 ? before_share > after_share : IsBetterMatch(before, after))
        position -= 1;
    } else if (standout >= 0 && before.matched) {
      // Accepted against its rivals: its neighbours are refused by the link share as it was; the one that shares the
      // larger part of its link with the key image is on the frame's side.
      const double after_share =
          has_next && after.matched ? SharedWithLink(after, route_[position], route_[position + 1]) : 0.0;
      if (SharedWithLink(before, route_[position - 1], route_[position]) > after_share) position -= 1;
    }
  }
  position_ = position;
  lost_in_a_row_ = 0;
  result.status = LocalizationStatus::kRelocalized;
  Describe(result, position_, features);
  return result;
}

Localizer::SecondLook Localizer::CompareLostFrameAgain(const Frame& frame, const ImageFeatures& features) {
  if (!lost_frame_matcher_) return SecondLook::kNothing;
  std::shared_ptr<const ImageFeatures> more;  // the frame's, extracted when first needed
  std::vector<KeyComparison> compared;        // with more features, chance's verdict aside
  const bool by_chance = CompareBestRankedAgain(frame, features, [&](int key) -> std::optional<KeyComparison> {
    const ImageFeatures* key_image = nullptr;
    try {
      key_image = &lost_frame_matcher_->KeyFeatures(key);
    } catch (const InputError&) {
      // The map's key image files are not at hand (its features came from the cache): its lost frames stay as they are.
      lost_frame_matcher_.reset();
      return std::nullopt;
    }
    const Matcher& matcher = lost_frame_matcher_->matcher();
    if (!more) more = matcher.ExtractFrame(frame.gray, frame.color);
    compared.push_back(comparer_.CompareImage(*more, *key_image, matcher.Match(*more, *key_image), key));
    return compared.back();
  });
  return by_chance ? SecondLook::kAccepted : AcceptLostFrameByHeading(compared, features);
}

Localizer::SecondLook Localizer::AcceptLostFrameByHeading(const std::vector<KeyComparison>& compared,
                                                          const ImageFeatures& features) {
  if (!options_.lost_frame_heading || !heading_accepts_ || options_.min_heading_rival_ratio <= 0.0 ||
      options_.lost_frame_heading_rival_ratio <= 0.0) {
    return SecondLook::kNothing;
  }
  // As HeadingStandsOut, with the frame's rivals among the comparisons made with as many features: a heading mode of
  // 4,000 features holds more votes at any key image than one of 500 (michigan_seasons' wrong key images 16-21, where
  // 500 features give them at most 15), so a rival of 500 would let almost any mode stand out.
  const auto best = std::max_element(
      compared.begin(), compared.end(),
      [](const KeyComparison& a, const KeyComparison& b) { return a.heading.votes < b.heading.votes; });
  if (best == compared.end() || !HeadingMayStandOut(*best)) return SecondLook::kNothing;
  const int position = route_position_of_key_[best->key];
  const int rival_votes = MostHeadingRivalVotes(position, compared);
  if (rival_votes < 0) return SecondLook::kNothing;
  SecondLook look = SecondLook::kAccepted;
  if (best->heading.votes < options_.lost_frame_heading_rival_ratio * rival_votes) {
    // Standing out less, a heading is a weaker witness: only where the route's order expects the frame (the corridor's
    // frame 20 at 1.5: a near rival four key images ahead of its estimate), and its heading is not steered by. Lost
    // frames move the robot on unseen, not back: behind the estimate the reach stays kNear (the kidnapped run's frame
    // 54 at the verifier's seed 11 took key image 14, six behind, and the frames after it were tracked there).
    const int offset = position - frame_start_position_;
    const bool near = options_.lost_frame_heading_near_ratio > 0.0 && frame_start_position_ >= 0 && offset >= -kNear &&
                      offset <= JumpReach(lost_in_a_row_) &&
                      best->heading.votes >= options_.lost_frame_heading_near_ratio * rival_votes;
    // Weaker still, only where the frame after one placed at the estimate is expected: at that key image, or the next
    // as a robot moving on goes (the wrong names of weaker headings point back, or are a run's first frames). A robot
    // that stops shows the same place again: a frame standing still stays.
    const bool next =
        !near && options_.lost_frame_next_heading_ratio > 0.0 && placed_before_ >= 0 &&
        placed_before_ == frame_start_position_ &&
        best->heading.votes >= options_.lost_frame_next_heading_ratio * rival_votes &&
        (position == placed_before_ || (position == placed_before_ + 1 && !StillSinceFrameBefore(features)));
    if (!near && !next) return SecondLook::kNothing;
    look = SecondLook::kPlacedOnly;
  }
  // A robot that stops cannot have moved several key images on: a frame standing still against the frame before shows
  // the place that frame showed, and its heading votes are that evidence counted again, which placed nothing there.
  // Beyond kNear of the estimate it is not placed by them, whichever ratio accepts it (bench/stop_check.py's noisy
  // row, 12->04 p2: the stopped robot relocalized three key images on by foliage's votes at 1.75 times its place's).
  if (frame_start_position_ >= 0 && std::abs(position - frame_start_position_) > kNear &&
      StillSinceFrameBefore(features)) {
    return SecondLook::kNothing;
  }
  for (Memo& m : comparisons_) {
    if (m.comparison.key != best->key) continue;
    // Weighed already as its first comparison was: WeighComparisons adds what the heading's acceptance adds.
    m.comparison = *best;
    m.comparison.accepted = m.by_heading = true;
  }
  return look;
}

bool Localizer::StillSinceFrameBefore(const ImageFeatures& features) const {
  if (features_before_.empty()) return false;
  const std::shared_ptr<const ImageFeatures> before = matcher_.DeserializeFeatures(features_before_);
  return before && StandsStill(matcher_, *before, features, options_.still_frame_share);
}

bool Localizer::SceneChangedSinceFrameBefore(const ImageFeatures& features) const {
  if (binary_descriptors_ || options_.scene_change_log10_nfa >= 0.0 || features_before_.empty()) return false;
  const std::shared_ptr<const ImageFeatures> before = matcher_.DeserializeFeatures(features_before_);
  if (!before) return false;
  // Verified and judged by chance as a comparison with a key image is, one test (not one of the frame's many).
  const PairComparison pair = ComparePair(matcher_, *before, features, options_.verifier, options_.similarity);
  return !pair.matched || ChanceOfComparison(pair, features.image_size(), before->image_size(), 1).log10_nfa >
                              options_.scene_change_log10_nfa;
}

double Localizer::SharedWithLink(const KeyComparison& comparison, int key_a, int key_b) const {
  for (const Link& link : map_.links) {
    if ((link.from_key == key_a && link.to_key == key_b) || (link.from_key == key_b && link.to_key == key_a)) {
      return link.num_verified > 0 ? static_cast<double>(comparison.num_verified) / link.num_verified : 0.0;
    }
  }
  return 0.0;  // no link between them: not comparable
}

}  // namespace vmap
