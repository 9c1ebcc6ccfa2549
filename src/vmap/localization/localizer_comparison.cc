// The Localizer's comparisons of a frame with key images: matching, verification, acceptance, heading and pose.
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "vmap/features/orb_matcher.h"
#include "vmap/geometry/pose_refinement.h"
#include "vmap/localization/localizer.h"

namespace vmap {

KeyComparison Localizer::Compare(const ImageFeatures& features, int key, int max_iterations) const {
  const ImageFeatures& key_image = *keys_.features[key];
  KeyComparison best = CompareImage(features, key_image, matcher_.Match(features, key_image), key, max_iterations);
  if (keys_.views.empty() || keys_.views[key].empty() || options_.experience_candidates == 0) return best;
  // Every view is matched (cheap); the few with the most tentative matches are verified.
  const std::vector<KeyImageView>& views = keys_.views[key];
  std::vector<TentativeMatches> matches;
  std::vector<int> order;
  for (size_t v = 0; v < views.size(); ++v) {
    matches.push_back(matcher_.Match(features, *views[v].features));
    order.push_back(static_cast<int>(v));
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return matches[a].size() > matches[b].size(); });
  order.resize(std::min<size_t>(order.size(), options_.experience_candidates));
  for (int v : order) {
    KeyComparison c = CompareImage(features, *views[v].features, matches[v], key, max_iterations);
    if (!FitsBetter(c, best)) continue;
    c.experience = views[v].experience;
    // Headings add up: x_frame - x_key = (x_frame - x_view) + (x_view - x_key).
    c.heading.px += views[v].heading_px;
    if (options_.camera && std::isfinite(c.heading.deg)) {
      // The view's offset as the bearing of a point it moves by that much at the image's centre.
      c.heading.deg += std::atan(views[v].heading_px / options_.camera->fx) * 180.0 / M_PI;
    }
    best = std::move(c);
  }
  return best;
}

KeyComparison Localizer::CompareImage(const ImageFeatures& features, const ImageFeatures& image,
                                      const TentativeMatches& matches, int key, int max_iterations) const {
  // As ComparePair, on matches made already.
  const int denominator = SimilarityDenominator(options_.similarity, static_cast<int>(matches.size()),
                                                features.num_features(), image.num_features());
  VerifierOptions verifier = options_.verifier;
  if (max_iterations > 0) verifier.max_iterations = std::min(verifier.max_iterations, max_iterations);
  const PairComparison pair = VerifyMatches(matches, denominator, verifier);
  KeyComparison c;
  c.key = key;
  c.matched = pair.matched;
  c.similarity = pair.similarity;
  c.num_tentative = pair.num_tentative;
  c.num_verified = pair.num_verified;
  c.F = pair.F;
  // Recorded whatever the rule, so that runs under either compare.
  if (pair.matched) {
    c.log10_nfa = ChanceOfComparison(pair, features.image_size(), image.image_size(),
                                     ComparisonsPerFrame(options_.lookahead, options_.relocalization_candidates))
                      .log10_nfa;
  }
  c.accepted =
      pair.matched && (options_.acceptance == AcceptanceRule::kChance
                           ? c.log10_nfa <= options_.max_log10_nfa && pair.num_verified >= LinkShareBar(key)
                           : pair.num_verified >= options_.min_verified && pair.similarity >= options_.min_similarity);
  // The heading from every tentative match (verified first, then rejected), key image -> frame.
  std::vector<cv::Point2f> key_points, frame_points;
  SplitCorrespondences(pair.correspondences, &frame_points, &key_points);
  std::vector<unsigned char> verified;
  if (pair.matched) {
    verified.assign(pair.correspondences.size(), 0);
    std::fill(verified.begin(), verified.begin() + pair.num_verified, 1);
  }
  const Camera* camera = options_.camera ? &*options_.camera : nullptr;
  c.heading = EstimateHeading(key_points, frame_points, verified, options_.heading, camera);
  if (pair.matched) c.verified.assign(pair.correspondences.begin(), pair.correspondences.begin() + pair.num_verified);
  return c;
}

void Localizer::AddPose(KeyComparison& c) const {
  if (!options_.camera || !c.matched || c.experience != 0 || c.verified.empty() || c.pose.valid) return;
  std::vector<cv::Point2f> key_points, frame_points;
  SplitCorrespondences(c.verified, &frame_points, &key_points);
  // The thresholds of the map's own pose estimates (PoseOptions): 3 px inliers, Cauchy scale 1 px.
  const PoseOptions pose_options;
  const double inlier_threshold = pose_options.refine_inlier_factor * pose_options.threshold;
  const NormalizedMatches verified_matches(*options_.camera, frame_points, key_points);
  RelativePose pose = PoseFromFundamental(c.F, verified_matches);
  if (!pose.valid) return;
  // F's pose is not an optimum of the matches' errors (E = K^T F K is not essential): refined, and the four
  // poses of the refined E decided again by cheirality, as a link's. Only then does the sigma below measure
  // the matches rather than how far F's pose is from their optimum.
  c.pose = EnforceCheirality(RefineRelativePose(pose, verified_matches, inlier_threshold, pose_options.threshold),
                             verified_matches, pose_options.threshold);
  const TranslationEvidence evidence =
      AssessTranslation(c.pose, verified_matches, verified_matches, pose_options, options_.translation);
  c.translation_sigma_deg = evidence.sigma_deg;
  c.translation_known = evidence.known;
}

int Localizer::TrackGuided(const Frame& frame, const ImageFeatures& features, int position, bool whatever_the_belief) {
  const int last = static_cast<int>(route_.size()) - 1;
  // Looser matching is decided by chance only (the counts rule would take its extra matches as evidence).
  if (!guided_matcher_ || options_.acceptance != AcceptanceRule::kChance) return -1;
  if (!whatever_the_belief && (!belief_confident_ || std::abs(belief_.Peak() - position) > kNear)) return -1;
  const int reach = options_.guided_lookahead ? options_.lookahead : 1;
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
    const KeyComparison first = CompareOnce(features, key);
    if (first.num_verified < LinkShareBar(key)) continue;
    WeighComparisons();  // the first comparisons' evidence, before a guided one replaces its key image's
    const TentativeMatches matches = guided_matcher_->Match(features, *keys_.features[key]);
    KeyComparison c = CompareImage(features, *keys_.features[key], matches, key);
    const bool by_chance = c.accepted;
    const double guided_log10_nfa = c.log10_nfa;
    const std::optional<double> predicted_dx = PreviousHeading(key);
    if (c.matched && !c.accepted && predicted_dx && !heading_before_is_a_guess_ &&
        HoldsContinuity(first, matches, *predicted_dx, features.image_size())) {
      c.accepted = true;
    }
    if (!c.accepted && options_.window_matching && predicted_dx && PassesContinuityGuards(first)) {
      if (window_matcher_ && !window_features) window_features = window_matcher_->ExtractFrame(frame.gray, frame.color);
      KeyComparison windowed =
          CompareInWindow(window_features ? *window_features : features, key, *predicted_dx, features.image_size());
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
  // The guided comparison replaces the first one's memo (CompareOnce made it above).
  for (Memo& m : comparisons_) {
    if (m.comparison.key == best.key) m = {std::move(best), /*weighed=*/true};
  }
  return found;
}

bool Localizer::CompareBestRankedAgain(const Frame& frame, const ImageFeatures& features,
                                       const std::function<std::optional<KeyComparison>(int key)>& again) {
  if (options_.acceptance != AcceptanceRule::kChance) return false;
  bool accepted = false;
  for (const int position : CompareBestRanked(frame, features)) {
    const int key = route_[position];
    const KeyComparison first = CompareOnce(features, key);
    // As TrackGuided: chance asked again, never the link share.
    if (first.accepted || first.num_verified < LinkShareBar(key)) continue;
    std::optional<KeyComparison> second = again(key);
    if (!second) break;
    WeighComparisons();  // the first comparison's evidence, before the second one replaces it
    if (!second->accepted) continue;
    const auto memo =
        std::find_if(comparisons_.begin(), comparisons_.end(), [&](const Memo& m) { return m.comparison.key == key; });
    *memo = {std::move(*second), /*weighed=*/true};  // CompareOnce made it
    accepted = true;
  }
  return accepted;
}

bool Localizer::GuideRelocalization(const Frame& frame, const ImageFeatures& features) {
  if (!guided_matcher_) return false;
  return CompareBestRankedAgain(frame, features, [&](int key) -> std::optional<KeyComparison> {
    const ImageFeatures& key_image = *keys_.features[key];
    return CompareImage(features, key_image, guided_matcher_->Match(features, key_image), key);
  });
}

std::optional<double> Localizer::PreviousHeading(int key) const {
  const auto previous = std::find_if(previous_headings_.begin(), previous_headings_.end(),
                                     [&](const std::pair<int, double>& h) { return h.first == key; });
  if (previous == previous_headings_.end()) return std::nullopt;
  return previous->second;
}

bool Localizer::HoldsContinuity(const KeyComparison& first, const TentativeMatches& guided, double predicted_dx,
                                cv::Size size) const {
  if (options_.continuity_share <= 0.0 || guided.size() == 0 || !PassesContinuityGuards(first)) return false;
  // The window of displacements around the prediction: those of bench/evidence_dump's near_L, where it was measured.
  const double half_width = size.width / 40.0, half_height = size.height / 20.0;
  int moving = 0;
  for (size_t i = 0; i < guided.size(); ++i) {
    const double dx = guided.points0[i].x - guided.points1[i].x, dy = guided.points0[i].y - guided.points1[i].y;
    moving += std::abs(dx - predicted_dx) <= half_width && std::abs(dy) <= half_height;
  }
  return moving >= options_.continuity_share * static_cast<double>(guided.size());
}

bool Localizer::PassesContinuityGuards(const KeyComparison& first) const {
  return !(first.heading.confidence < options_.continuity_heading_confidence) &&
         first.log10_nfa <= options_.continuity_max_log10_nfa;
}

KeyComparison Localizer::CompareInWindow(const ImageFeatures& window_features, int key, double predicted_dx,
                                         cv::Size size) const {
  MatchWindow window;
  window.predicted_dx = predicted_dx;
  window.half_width = options_.window_width * size.width;
  window.half_height = size.height / 20.0;
  window.zoom = options_.window_zoom;
  window.centre = cv::Point2f(size.width / 2.0f, size.height / 2.0f);
  const ImageFeatures& key_features = *keys_.features[key];
  KeyComparison c =
      CompareImage(window_features, key_features, MatchOrbInWindow(window_features, key_features, window), key);
  // Chance's test counts matches that agree with the prediction by construction: its own threshold, measured.
  c.accepted = c.matched && c.log10_nfa <= options_.window_max_log10_nfa;
  return c;
}

KeyComparison Localizer::CompareOnce(const ImageFeatures& features, int key) {
  for (const Memo& m : comparisons_) {
    if (m.comparison.key == key) return m.comparison;
  }
  // Made before the frame got here (LocalizeSequence's workers), meanwhile (speculation_) or now: recorded only when
  // asked for, so the memo holds what the frame asked for in the order it asked, and every sum over it is as when
  // each comparison is made in turn.
  std::optional<KeyComparison> made;
  const auto ahead =
      std::find_if(made_ahead_.begin(), made_ahead_.end(), [&](const KeyComparison& c) { return c.key == key; });
  if (ahead != made_ahead_.end()) {
    made = std::move(*ahead);
  } else if (speculation_) {
    made = speculation_->Take(key);
  }
  comparisons_.push_back({made ? std::move(*made) : Compare(features, key, FarComparisonIterations(key))});
  return comparisons_.back().comparison;
}

int Localizer::FarComparisonIterations(int key) const {
  if (options_.far_comparison_iterations <= 0 || !binary_descriptors_) return 0;
  // The tracker's own key images are verified in full: the one behind the estimate (a step back), the estimate's, the
  // `lookahead` after it and the next key image of the furthest step on (its guidance). Without an estimate (a run's
  // start, a drop) the frame is relocalized: all in full.
  const int p = route_position_of_key_[key];
  const int from = frame_start_position_;
  if (from < 0 || (p >= from - 1 && p <= from + options_.lookahead + 1)) return 0;
  return options_.far_comparison_iterations;
}

void Localizer::CompareMeanwhile(const ImageFeatures& features, const std::vector<int>& positions) {
  if (!speculation_) return;
  std::vector<int> keys;
  for (int p : positions) {
    if (p < 0 || p >= static_cast<int>(route_.size())) continue;
    const int key = route_[p];
    const auto has_key = [&](const KeyComparison& c) { return c.key == key; };
    if (std::none_of(comparisons_.begin(), comparisons_.end(), [&](const Memo& m) { return has_key(m.comparison); }) &&
        std::none_of(made_ahead_.begin(), made_ahead_.end(), has_key))
      keys.push_back(key);
  }
  if (!keys.empty()) speculation_->Add(features, keys);
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
