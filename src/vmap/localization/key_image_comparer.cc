#include "vmap/localization/key_image_comparer.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "vmap/features/orb_matcher.h"
#include "vmap/geometry/heading.h"
#include "vmap/geometry/pose_refinement.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/geometry/translation_evidence.h"
#include "vmap/localization/acceptance.h"
#include "vmap/mapping/key_image_selector.h"

namespace vmap {

KeyImageComparer::KeyImageComparer(const KeyImageStore& keys, const Matcher& matcher, LocalizerOptions options)
    : keys_(keys), matcher_(matcher), options_(std::move(options)) {}

KeyComparison KeyImageComparer::Compare(const ImageFeatures& features, int key, int max_iterations) const {
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

KeyComparison KeyImageComparer::CompareImage(const ImageFeatures& features, const ImageFeatures& image,
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

void KeyImageComparer::AddPose(KeyComparison& c) const {
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

KeyComparison KeyImageComparer::CompareInWindow(const ImageFeatures& window_features, int key, double predicted_dx,
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

}  // namespace vmap
