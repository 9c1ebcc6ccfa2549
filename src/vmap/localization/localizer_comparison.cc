// The Localizer's comparisons made again or guided (guided matching, the continuity of the heading, matching within
// the prediction's window), the iterations of those away from the tracker, and the comparisons' own tests.
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "vmap/localization/localizer.h"

namespace vmap {

int Localizer::TrackGuided(const Frame& frame, const ImageFeatures& features, int position, bool whatever_the_belief) {
  const int last = static_cast<int>(route_.size()) - 1;
  // Looser matching is decided by chance only (the counts rule would take its extra matches as evidence).
  if (!guided_matcher_ || options_.acceptance != AcceptanceRule::kChance) return -1;
  if (!whatever_the_belief && (!belief_confident_ || std::abs(belief_.Peak() - position) > kNear)) return -1;
  const int reach = options_.guided_lookahead ? lookahead_ : 1;
  int found = -1;
  KeyComparison best;
  // The best's one-way guided comparison: its log10 NFA, and whether chance accepted it.
  double best_guided_log10_nfa = 0.0;
  bool best_by_chance = false;
  std::shared_ptr<const ImageFeatures> window_features;  // window_matcher_'s, extracted when first needed
  // Every key image of the loop below is compared first: those after `position` are made meanwhile.
  std::vector<int> after;
  for (int p = std::min(last, position + reach); p > position; --p) after.push_back(p);
  CompareMeanwhile(features, after);
  for (int p = position; p <= std::min(last, position + reach); ++p) {
    const int key = route_[p];
    // Only where chance refused the first comparison and the link share did not: guided matching asks chance again,
    // never the share (a frame that shares little with the key image's scene, seen from elsewhere, stays refused:
    // redkitchen's teach/repeat run, docs/localize.md).
    const KeyComparison first = comparisons_.Once(features, key);
    if (first.num_verified < comparer_.LinkShareBar(key)) continue;
    WeighComparisons();  // the first comparisons' evidence, before a guided one replaces its key image's
    const TentativeMatches matches = guided_matcher_->Match(features, *keys_.features[key]);
    KeyComparison c = comparer_.CompareImage(features, *keys_.features[key], matches, key);
    const bool by_chance = c.accepted;
    const double guided_log10_nfa = c.log10_nfa;
    const std::optional<double> predicted_dx = continuity_.Predicted(key);
    if (c.matched && !c.accepted && predicted_dx && !continuity_.follows_a_guess() &&
        continuity_.Holds(first, matches, *predicted_dx, features.image_size())) {
      c.accepted = true;
    }
    if (!c.accepted && options_.window_matching && predicted_dx && continuity_.PassesGuards(first)) {
      if (window_matcher_ && !window_features) window_features = window_matcher_->ExtractFrame(frame.gray, frame.color);
      KeyComparison windowed = comparer_.CompareInWindow(window_features ? *window_features : features, key,
                                                         *predicted_dx, features.image_size());
      if (windowed.accepted) c = std::move(windowed);
    }
    if (!c.accepted) continue;
    if (found >= 0) {
      // One measure for every candidate: chance's verified matches where chance accepts, else the one-way NFA.
      const bool better = !options_.guided_lookahead    ? IsBetterMatch(c, best)
                          : by_chance != best_by_chance ? by_chance
                          : by_chance                   ? IsBetterMatch(c, best)
                                                        : guided_log10_nfa < best_guided_log10_nfa;
      if (!better) continue;
    }
    found = p;
    best = std::move(c);
    best_guided_log10_nfa = guided_log10_nfa;
    best_by_chance = by_chance;
  }
  if (found < 0) return -1;
  comparisons_.Replace(std::move(best));  // the first comparison's memo, made above
  return found;
}

bool Localizer::CompareBestRankedAgain(const Frame& frame, const ImageFeatures& features,
                                       const std::function<std::optional<KeyComparison>(int key)>& again) {
  if (options_.acceptance != AcceptanceRule::kChance) return false;
  bool accepted = false;
  for (const int position : CompareBestRanked(frame, features)) {
    const int key = route_[position];
    const KeyComparison first = comparisons_.Once(features, key);
    // As TrackGuided: chance asked again, never the link share.
    if (first.accepted || first.num_verified < comparer_.LinkShareBar(key)) continue;
    std::optional<KeyComparison> second = again(key);
    if (!second) break;
    WeighComparisons();  // the first comparison's evidence, before the second one replaces it
    if (!second->accepted) continue;
    comparisons_.Replace(std::move(*second));
    accepted = true;
  }
  return accepted;
}

bool Localizer::GuideRelocalization(const Frame& frame, const ImageFeatures& features) {
  if (!guided_matcher_) return false;
  return CompareBestRankedAgain(frame, features, [&](int key) -> std::optional<KeyComparison> {
    const ImageFeatures& key_image = *keys_.features[key];
    return comparer_.CompareImage(features, key_image, guided_matcher_->Match(features, key_image), key);
  });
}

int Localizer::FarComparisonIterations(int key) const {
  if (options_.far_comparison_iterations <= 0 || !binary_descriptors_) return 0;
  // The tracker's own key images are verified in full: the one behind the estimate (a step back), the estimate's, the
  // `lookahead` after it and the next key image of the furthest step on (its guidance). Without an estimate (a run's
  // start, a drop) the frame is relocalized: all in full.
  const int p = route_position_of_key_[key];
  const int from = frame_start_position_;
  if (from < 0 || (p >= from - 1 && p <= from + lookahead_ + 1)) return 0;
  return options_.far_comparison_iterations;
}

void Localizer::CompareMeanwhile(const ImageFeatures& features, const std::vector<int>& positions) {
  std::vector<int> keys;
  for (const int p : positions) {
    if (p >= 0 && p < static_cast<int>(route_.size())) keys.push_back(route_[p]);
  }
  comparisons_.Meanwhile(features, keys);
}

bool Localizer::NoLikelierChance(const KeyComparison& to, const KeyComparison& from) const {
  // Beyond the evidence's bound both are the same scene beyond doubt (redkitchen's frames verify at -200 to -460), and
  // the count alone ranks them, as the bracket test chose.
  const double beyond_doubt = -evidence_.max_significance;
  return std::max(to.log10_nfa, beyond_doubt) <= std::max(from.log10_nfa, beyond_doubt);
}

bool Localizer::SharesLittle(const KeyComparison& comparison) const {
  const int reference = link_verified_[comparison.key];
  return reference > 0 && comparison.num_verified < options_.recheck_link_share * reference;
}

}  // namespace vmap
