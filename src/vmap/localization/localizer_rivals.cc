// The acceptance of a frame against its own rivals (LocalizerOptions::min_rival_ratio): the map's links are of one
// season, and across seasons they refuse every key image a frame is compared with, the right one too. The key image
// that stands far above those compared elsewhere on the route is then accepted: it is the frame's place, not only
// its scene, as far as the frame itself can tell. And the rival place (LocalizerOptions::rival_place_frames) compared
// by the frames not steered by, and the place the run moved back to (LocalizerOptions::ask_where_moved_back).
#include <algorithm>
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

std::vector<RankedKey> Localizer::RouteRanking(const Frame& frame, const ImageFeatures& features) const {
  const cv::Mat thumbnail = ranking_->method() == RankingMethod::kThumbnails
                                ? ThumbnailDescriptor(frame.gray, options_.ranking.thumbnail_width)
                                : cv::Mat();
  return ranking_->Rank(features, thumbnail);
}

const std::vector<RankedKey>& Localizer::RankRoute(const Frame& frame, const ImageFeatures& features) {
  if (ranked_.empty()) ranked_ = RouteRanking(frame, features);
  return ranked_;
}

int Localizer::RivalVerified(const Frame& frame, const ImageFeatures& features, int position) {
  // The best-ranked key image more than kNear away is always a rival: the likeliest other place, as the frame's
  // descriptors tell (a relocalization has compared it already; a tracked frame compares it now, one comparison where
  // a relocalization makes five).
  for (const RankedKey& r : RankRoute(frame, features)) {
    if (std::abs(r.key - position) > kNear) {
      comparisons_.Once(features, route_[r.key]);  // the ranking holds the route's key images in route order
      break;
    }
  }
  return MostVerifiedAway(position, /*accepted_only=*/false);
}

int Localizer::MostVerifiedAway(int position, bool accepted_only) const {
  int most = -1;
  for (const Memo& m : comparisons_) {
    const int q = route_position_of_key_[m.comparison.key];
    if (q >= 0 && std::abs(q - position) > kNear && (m.comparison.accepted || !accepted_only)) {
      most = std::max(most, m.comparison.num_verified);
    }
  }
  return most;
}

bool Localizer::MayStandOut(const KeyComparison& comparison) const {
  return options_.acceptance == AcceptanceRule::kChance && options_.min_rival_ratio > 0.0 && comparison.matched &&
         comparison.log10_nfa <= options_.rival_max_log10_nfa;
}

bool Localizer::StandsOut(int verified, int rival_verified) const {
  // No rival: a route too short to hold one (5 key images, the frame in the middle): the frame cannot tell.
  return rival_verified >= 0 && verified >= options_.min_rival_ratio * rival_verified;
}

bool Localizer::IsHeadingRival(int position, int q) const {
  if (q == position) return false;
  if (std::abs(q - position) > kNear) return true;
  for (int p = std::min(q, position); p < std::max(q, position); ++p) {
    if (!scene_link_after_[p]) return true;
  }
  return false;
}

namespace {

const KeyComparison& ComparisonOf(const FrameComparisons::Memo& memo) { return memo.comparison; }
const KeyComparison& ComparisonOf(const KeyComparison& comparison) { return comparison; }

}  // namespace

template <typename Compared>
int Localizer::MostHeadingRivalVotes(int position, const Compared& compared) const {
  int rival_votes = -1;
  for (const auto& c : compared) {
    const KeyComparison& rival = ComparisonOf(c);
    const int q = route_position_of_key_[rival.key];
    if (q >= 0 && IsHeadingRival(position, q)) rival_votes = std::max(rival_votes, rival.heading.votes);
  }
  return rival_votes;
}

template int Localizer::MostHeadingRivalVotes(int, const FrameComparisons&) const;
template int Localizer::MostHeadingRivalVotes(int, const std::vector<KeyComparison>&) const;

bool Localizer::HeadingMayStandOut(const KeyComparison& comparison) const {
  // The heading answers chance only, never the link share: a frame that shares little with a key image's place sees
  // its scene from elsewhere, and the scene's matches agree there too (redkitchen's teach/repeat run: 2 -> 57 frames
  // steered by wrong when the heading overrode the share).
  return comparison.matched && comparison.heading.votes >= options_.min_heading_votes &&
         comparison.num_verified >= comparer_.LinkShareBar(comparison.key);
}

bool Localizer::HeadingStandsOut(const Frame& frame, const ImageFeatures& features, const KeyComparison& comparison,
                                 int position) {
  if (!heading_accepts_ || options_.acceptance != AcceptanceRule::kChance || options_.min_heading_rival_ratio <= 0.0 ||
      comparison.log10_nfa <= options_.max_log10_nfa || !HeadingMayStandOut(comparison)) {
    return false;
  }
  // The likeliest other place, as the frame's descriptors tell, is always among the rivals.
  for (const RankedKey& r : RankRoute(frame, features)) {
    if (IsHeadingRival(position, r.key)) {
      comparisons_.Once(features, route_[r.key]);  // the ranking holds the route's key images in route order
      break;
    }
  }
  const int rival_votes = MostHeadingRivalVotes(position, comparisons_);
  return rival_votes >= 0 && comparison.heading.votes >= options_.min_heading_rival_ratio * rival_votes;
}

int Localizer::AcceptByHeading(const Frame& frame, const ImageFeatures& features) {
  int best = -1;  // index in comparisons_ (HeadingStandsOut may grow it)
  for (size_t i = 0; i < comparisons_.size(); ++i) {
    const Memo& m = comparisons_[i];
    if (route_position_of_key_[m.comparison.key] < 0) continue;
    if (best < 0 || m.comparison.heading.votes > comparisons_[best].comparison.heading.votes)
      best = static_cast<int>(i);
  }
  if (best < 0) return -1;
  const KeyComparison candidate = comparisons_[best].comparison;
  const int position = route_position_of_key_[candidate.key];
  if (!HeadingStandsOut(frame, features, candidate, position)) return -1;
  for (Memo& m : comparisons_) {
    if (m.comparison.key == candidate.key) m.comparison.accepted = m.by_heading = true;
  }
  return position;
}

KeyComparison Localizer::CompareTracked(const Frame& frame, const ImageFeatures& features, int position) {
  const int key = route_[position];
  KeyComparison c = comparisons_.Once(features, key);
  if (c.accepted) return c;
  // Refused: its rivals are compared now, and Track's key images after the tracked one and before it meanwhile.
  std::vector<int> tracked;
  for (int step = 1; step <= lookahead_; ++step) tracked.push_back(position_ + step);
  tracked.push_back(position_ - 1);
  CompareMeanwhile(features, tracked);
  const bool by_verified = MayStandOut(c) && StandsOut(c.num_verified, RivalVerified(frame, features, position));
  const bool by_heading = !by_verified && HeadingStandsOut(frame, features, c, position);
  if (!by_verified && !by_heading) return c;
  for (Memo& m : comparisons_) {
    if (m.comparison.key == key) {
      m.comparison.accepted = true;
      m.by_heading = by_heading;
    }
  }
  c.accepted = true;
  return c;
}

bool Localizer::AcceptedAgainstRivals(const KeyComparison& comparison) const {
  return comparison.accepted && options_.acceptance == AcceptanceRule::kChance &&
         comparison.num_verified < comparer_.LinkShareBar(comparison.key);
}

int Localizer::AcceptAgainstRivals(const Frame& frame, const ImageFeatures& features) {
  auto position_of = [&](const Memo& m) { return route_position_of_key_[m.comparison.key]; };
  int best = -1;  // index in comparisons_ (comparisons_.Once below may grow it)
  for (size_t i = 0; i < comparisons_.size(); ++i) {
    const Memo& m = comparisons_[i];
    if (position_of(m) < 0) continue;
    if (m.comparison.accepted) return -1;  // the link share accepted one: nothing to decide here
    if (best < 0 || m.comparison.num_verified > comparisons_[best].comparison.num_verified) best = static_cast<int>(i);
  }
  if (best < 0) return -1;
  const int position = route_position_of_key_[comparisons_[best].comparison.key];
  if (!MayStandOut(comparisons_[best].comparison) ||
      !StandsOut(comparisons_[best].comparison.num_verified, RivalVerified(frame, features, position))) {
    return AcceptByHeading(frame, features);
  }
  comparisons_[best].comparison.accepted = true;
  return position;
}

void Localizer::CompareRivalPlace(const LocalizationResult& result, const ImageFeatures& features) {
  const bool steered = IsPlaced(result.status);
  if (!options_.rival_place_when_not_steered || steered || rival_place_ < 0) return;
  const int last = static_cast<int>(route_.size()) - 1;
  for (int q = rival_place_; q <= std::min(last, rival_place_ + 1); ++q) comparisons_.Once(features, route_[q]);
}

void Localizer::RememberRivalPlace(const LocalizationResult& result) {
  if (rival_place_ >= 0 && --rival_frames_left_ <= 0) rival_place_ = -1;
  const bool placed = IsPlaced(result.status);
  if (options_.rival_place_frames <= 0 || (!placed && !options_.rival_place_when_not_steered) ||
      result.route_position < 0) {
    return;
  }
  const int rival = OutVerifiedFrom(result);
  if (rival < 0) return;
  rival_place_ = rival;
  rival_frames_left_ = options_.rival_place_frames;
}

void Localizer::RememberMoveBack(const LocalizationResult& result) {
  if (!IsPlaced(result.status)) return;  // an uncertain or lost frame moves nothing the frames after it follow
  if (steered_before_ >= 0 && result.route_position < steered_before_) {
    moved_back_to_ = result.route_position;
  } else if (result.route_position != moved_back_to_) {
    moved_back_to_ = -1;  // moved on, or placed elsewhere ahead
  }
  steered_before_ = result.route_position;
}

int Localizer::OutVerifiedFrom(const LocalizationResult& result) const {
  int most = 0;  // the verified matches of the key images the frame is placed at
  for (const KeyComparison* c : {&result.to_key, &result.to_next}) {
    if (c->accepted) most = std::max(most, c->num_verified);
  }
  int rival = -1;
  for (const Memo& m : comparisons_) {
    const KeyComparison& c = m.comparison;
    const int p = route_position_of_key_[c.key];
    if (!c.accepted || p < 0 || std::abs(p - result.route_position) <= kNear) continue;
    if (c.num_verified > most) {
      most = c.num_verified;
      rival = p;
    }
  }
  return rival;
}

}  // namespace vmap
