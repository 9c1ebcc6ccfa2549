#include "vmap/localization/localizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "vmap/core/error.h"

namespace vmap {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A previous key image with fewer verified matches than this share of the key image's is clearly the worse
// match: the step back is not checked again until the frame moves back (Localizer::Track). 0.7 spared 58 % of
// the checks of XFeat's lab_floor run and moved no frame (docs/localize.md).
constexpr double kClearlyWorse = 0.7;

// Which of two accepted comparisons is the better match: more verified matches, then higher S.
// Measured on the bracket test (docs/measurements/localization.md): S first, S times verified, a 10 % or 25 % margin
// before moving on, and moving on only when S is higher too localized no more odd frames of redkitchen between their
// key images than verified matches alone.
bool Better(const KeyComparison& a, const KeyComparison& b) {
  if (!a.accepted) return false;
  if (!b.accepted) return true;
  if (a.num_verified != b.num_verified) return a.num_verified > b.num_verified;
  return a.similarity > b.similarity;
}

// Which of two images of one key image (the key image, a view) fits a frame better: the better match by
// Better, and when neither is accepted, more verified matches (the heading is still reported). Ties keep the
// first (the teach key image).
bool FitsBetter(const KeyComparison& a, const KeyComparison& b) {
  if (a.accepted || b.accepted) return Better(a, b);
  if (a.num_verified != b.num_verified) return a.num_verified > b.num_verified;
  return a.similarity > b.similarity;
}

}  // namespace

std::string LocalizationStatusName(LocalizationStatus status) { return EnumToName(kLocalizationStatusNames, status); }

void LocalizerOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"acceptance", "--acceptance",
                 "When a frame is seen at a key image: chance (its verified matches are unlikely by "
                 "chance, --max-log10-nfa, and many against the map's links, --min-link-share) or "
                 "counts (the earlier rule: --min-verified and --min-similarity)"},
                EnumField(acceptance, kAcceptanceRuleNames, ParseAcceptanceRule));
  visitor.Visit({"max_log10_nfa", "--max-log10-nfa",
                 "--acceptance chance: accept when log10 of the number of false alarms is at most this"},
                max_log10_nfa);
  visitor.Visit({"min_verified", "--min-verified",
                 "--acceptance counts: verified matches a frame needs to be localized at a key image"},
                min_verified);
  visitor.Visit(
      {"min_similarity", "--min-similarity", "--acceptance counts: S a frame needs to be localized at a key image"},
      min_similarity);
  visitor.Visit({"min_link_share", "--min-link-share",
                 "--acceptance chance: verified matches a frame also needs, as a fraction of those of the key "
                 "image's link with its route neighbour (0: chance alone)"},
                min_link_share);
  visitor.Visit({"recheck_link_share", "--recheck-link-share",
                 "Relocalize a tracked frame with fewer verified matches than this fraction of its key image's "
                 "link, and move it where more verify (0: never)"},
                recheck_link_share);
  visitor.Visit({"max_lost_frames", "--max-lost", "Lost frames in a row before the estimate is dropped"},
                max_lost_frames);
  visitor.Visit({"relocalization_candidates", "--candidates", "Best-ranked key images verified when relocalizing"},
                relocalization_candidates);
  visitor.Visit({"experience_candidates", "--experience-candidates",
                 "Maps with experiences: views of a key image verified besides it, those with the most tentative "
                 "matches (0 = the teach key images only)"},
                experience_candidates);
  visitor.Visit({"lookahead", "--lookahead", "Key images beyond the next compared while tracking (1 or 2)"}, lookahead);
  visitor.Visit({"step_back", "!--no-step-back", "Never move the estimate back to the previous key image"}, step_back);
  visitor.VisitNested("ranking", ranking);
  visitor.VisitNested("heading", heading);
  visitor.VisitNested("verifier", verifier, Nesting{false, {"max_samples_to_reject"}});
  visitor.VisitNested("translation", translation);
  visitor.Visit({"similarity"}, EnumField(similarity, kSimilarityModeNames, ParseSimilarityMode));
  visitor.Visit({"route"}, route);
}

void LocalizerOptions::Check() const {
  const LocalizerOptions defaults;  // the defaults the messages give, as declared
  if (min_verified < 8 || min_verified > 100000) {
    throw OptionError("min_verified", fmt::format("{} must be 8 (the fewest matches F can be verified with) to "
                                                  "100000 (default {})",
                                                  min_verified, defaults.min_verified));
  }
  if (!(min_similarity >= 0.0 && min_similarity <= 1.0)) {
    throw OptionError("min_similarity",
                      fmt::format("{} is outside [0, 1] (default {})", min_similarity, defaults.min_similarity));
  }
  if (!(max_log10_nfa >= -1000.0 && max_log10_nfa <= 1000.0)) {
    throw OptionError("max_log10_nfa", fmt::format("{} is outside [-1000, 1000] (default {}; 0: accept what "
                                                   "chance explains less than once)",
                                                   max_log10_nfa, defaults.max_log10_nfa));
  }
  if (!(recheck_link_share >= 0.0 && recheck_link_share <= 10.0)) {
    throw OptionError("recheck_link_share",
                      fmt::format("{} is outside [0, 10] (default {}; 0: never relocalize a tracked frame)",
                                  recheck_link_share, defaults.recheck_link_share));
  }
  if (!(min_link_share >= 0.0 && min_link_share <= 10.0)) {
    throw OptionError("min_link_share", fmt::format("{} is outside [0, 10] (default {}; 0: chance alone decides)",
                                                    min_link_share, defaults.min_link_share));
  }
  if (lookahead < 1 || lookahead > 2) {
    throw OptionError("lookahead", fmt::format("{} is not 1 or 2 (default {})", lookahead, defaults.lookahead));
  }
  if (max_lost_frames < 0 || max_lost_frames > 1000000) {
    throw OptionError("max_lost_frames",
                      fmt::format("{} must be 0 to 1000000 (default {})", max_lost_frames, defaults.max_lost_frames));
  }
  if (relocalization_candidates < 1 || relocalization_candidates > 10000) {
    throw OptionError("relocalization_candidates",
                      fmt::format("{} must be 1 to 10000 (default {})", relocalization_candidates,
                                  defaults.relocalization_candidates));
  }
  CheckField("ranking", ranking);
  CheckField("verifier", verifier);
  CheckField("heading", heading);
  CheckField("translation", translation);
  if (experience_candidates < 0 || experience_candidates > 1000) {
    throw OptionError("experience_candidates", fmt::format("{} must be 0 (teach key images only) to 1000 (default {})",
                                                           experience_candidates, defaults.experience_candidates));
  }
}

std::pair<int, int> KeysAround(const VisualMap& map, int source_index) {
  int before = -1, after = -1;
  for (int k = 0; k < static_cast<int>(map.key_images.size()); ++k) {
    const int s = map.key_images[k].source_index;
    if (s <= source_index && (before < 0 || s >= map.key_images[before].source_index)) before = k;
    if (s >= source_index && (after < 0 || s < map.key_images[after].source_index)) after = k;
  }
  return {before, after};
}

VerifierOptions MapVerifierOptions(const VerifierOptions& recorded, int max_iterations, int loop_points) {
  // ORB's matches (no scores) keep the map's verifier with the cap localization always had.
  constexpr int kUnscoredMaxIterations = 5000;
  VerifierOptions options = recorded;
  options.max_iterations = std::min(options.max_iterations, kUnscoredMaxIterations);
  // Scored matches: at most `max_iterations` samples on the `loop_points` best-scored ones.
  options.loop_points = loop_points;
  options.max_samples_to_reject = std::min(options.max_iterations, max_iterations);
  options.Check();
  return options;
}

std::string LocalizationGuidance(const LocalizationResult& result) {
  if (result.status == LocalizationStatus::kLost) return "none: lost";
  if (result.status == LocalizationStatus::kUncertain) return "none: position uncertain";
  if (!std::isfinite(result.heading_px)) return "none";
  const KeyComparison& target = result.next_key >= 0 ? result.to_next : result.to_key;
  if (!target.pose.valid) return "heading only: no pose";
  return result.translation_known ? "heading and translation" : "heading only: translation unknown";
}

bool MaySteerBy(const LocalizationResult& result) {
  return (result.status == LocalizationStatus::kTracking || result.status == LocalizationStatus::kRelocalized) &&
         std::isfinite(result.heading_px);
}

Localizer::Localizer(const VisualMap& map, const KeyImageStore& keys, const Matcher& matcher, LocalizerOptions options)
    : map_(map), keys_(keys), matcher_(matcher), options_(std::move(options)) {
  options_.Check();
  const int num_keys = static_cast<int>(map_.key_images.size());
  if (num_keys == 0) throw InputError("the map has no key images; nothing to localize against");
  if (!keys_.views.empty() && static_cast<int>(keys_.views.size()) != num_keys) {
    throw InputError("the experiences' views do not belong to this map; load them with LoadKeyImageStore");
  }
  if (static_cast<int>(keys_.features.size()) != num_keys || static_cast<int>(keys_.thumbnails.size()) != num_keys) {
    throw InputError("the key-image features do not belong to this map; load them with LoadKeyImageStore");
  }
  route_ = options_.route;
  if (route_.empty()) {
    for (int k = 0; k < num_keys; ++k) route_.push_back(k);
  }
  route_position_of_key_.assign(num_keys, -1);
  for (size_t p = 0; p < route_.size(); ++p) {
    const int k = route_[p];
    if (k < 0 || k >= num_keys) {
      throw InputError(fmt::format("route names key image {}, but the map has key images 0 to {}", k, num_keys - 1));
    }
    if (route_position_of_key_[k] >= 0) throw InputError(fmt::format("route visits key image {} twice", k));
    route_position_of_key_[k] = static_cast<int>(p);
  }
  link_verified_.assign(num_keys, 0);
  for (const Link& link : map_.links) {
    const int a = link.from_key, b = link.to_key;
    if (a < 0 || b < 0 || a >= num_keys || b >= num_keys || route_position_of_key_[a] < 0 ||
        route_position_of_key_[b] < 0 || std::abs(route_position_of_key_[a] - route_position_of_key_[b]) != 1 ||
        !link.has_fundamental || link.num_verified <= 0) {
      continue;
    }
    for (const int k : {a, b}) {
      link_verified_[k] = link_verified_[k] > 0 ? std::min(link_verified_[k], link.num_verified) : link.num_verified;
    }
  }
  // Only the route's key images take part in the ranking.
  std::vector<std::shared_ptr<const ImageFeatures>> features;
  std::vector<cv::Mat> thumbnails;
  for (int k : route_) {
    features.push_back(keys_.features[k]);
    thumbnails.push_back(keys_.thumbnails[k]);
  }
  ranking_ = std::make_unique<KeyImageRanking>(features, thumbnails, options_.ranking);
}

Localizer::~Localizer() = default;

void Localizer::Reset() {
  position_ = -1;
  lost_in_a_row_ = 0;
  step_back_ruled_out_ = {};
}

KeyComparison Localizer::Compare(const ImageFeatures& features, int key) const {
  const ImageFeatures& key_image = *keys_.features[key];
  KeyComparison best = CompareImage(features, key_image, matcher_.Match(features, key_image), key);
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
    KeyComparison c = CompareImage(features, *views[v].features, matches[v], key);
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
                                      const TentativeMatches& matches, int key) const {
  // As ComparePair, on matches made already.
  const int denominator = SimilarityDenominator(options_.similarity, static_cast<int>(matches.size()),
                                                features.num_features(), image.num_features());
  const PairComparison pair = VerifyMatches(matches, denominator, options_.verifier);
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
      pair.matched &&
      (options_.acceptance == AcceptanceRule::kChance
           ? c.log10_nfa <= options_.max_log10_nfa && pair.num_verified >= options_.min_link_share * link_verified_[key]
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

LocalizationResult Localizer::Localize(const Frame& frame, const ImageFeatures& features,
                                       std::vector<KeyComparison> ahead) {
  const auto start = std::chrono::steady_clock::now();
  comparisons_.clear();
  for (KeyComparison& c : ahead) {
    if (c.key >= 0 && c.key < static_cast<int>(keys_.features.size())) comparisons_.push_back({std::move(c), false});
  }
  LocalizationResult result = has_estimate() ? Track(frame, features) : Relocalize(frame, features);
  result.comparisons =
      static_cast<int>(std::count_if(comparisons_.begin(), comparisons_.end(), [](const Memo& m) { return m.used; }));
  if (result.key >= 0 && result.to_key.key == result.key) {
    result.key_rank = 1 + static_cast<int>(std::count_if(comparisons_.begin(), comparisons_.end(), [&](const Memo& m) {
                        return m.used && m.comparison.key != result.key && FitsBetter(m.comparison, result.to_key);
                      }));
  }
  result.frame_index = frame.index;
  result.source_index = frame.source_index;
  result.timestamp = frame.timestamp;
  result.source_name = frame.source_name;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<int> Localizer::LikelyKeys() const {
  if (!has_estimate()) return {};
  std::vector<int> keys = {route_[position_]};
  if (position_ + 1 < static_cast<int>(route_.size())) keys.push_back(route_[position_ + 1]);
  return keys;
}

KeyComparison Localizer::CompareOnce(const ImageFeatures& features, int key) {
  for (Memo& m : comparisons_) {
    if (m.comparison.key == key) {
      m.used = true;
      return m.comparison;
    }
  }
  comparisons_.push_back({Compare(features, key), true});
  return comparisons_.back().comparison;
}

// Fills key, next_key, their comparisons, heading and progress for the estimate at route `position`.
void Localizer::Describe(LocalizationResult& result, int position, const ImageFeatures& features) {
  result.route_position = position;
  result.key = route_[position];
  result.to_key = CompareOnce(features, result.key);
  const bool at_end = position + 1 >= static_cast<int>(route_.size());
  result.next_key = at_end ? -1 : route_[position + 1];
  result.to_next = at_end ? KeyComparison() : CompareOnce(features, result.next_key);
  KeyComparison& target = at_end ? result.to_key : result.to_next;
  AddPose(target);
  result.heading_px = target.heading.px;
  result.heading_deg = target.heading.deg;
  result.heading_key_px = result.to_key.heading.px;
  result.heading_key_deg = result.to_key.heading.deg;
  result.translation_known = target.matched && target.pose.valid && target.translation_known;
  if (at_end) {
    result.progress = result.to_key.accepted ? 0.0 : kNaN;
  } else {
    const int v_key = result.to_key.accepted ? result.to_key.num_verified : 0;
    const int v_next = result.to_next.accepted ? result.to_next.num_verified : 0;
    result.progress = v_key + v_next > 0 ? static_cast<double>(v_next) / (v_key + v_next) : kNaN;
  }
}

LocalizationResult Localizer::Track(const Frame& frame, const ImageFeatures& features) {
  LocalizationResult result;
  const int last = static_cast<int>(route_.size()) - 1;
  auto compare_at = [&](int position) { return CompareOnce(features, route_[position]); };
  const int position = position_;
  const KeyComparison at_key = compare_at(position);
  KeyComparison best = at_key;
  int best_position = position;
  // Move on while the key image ahead is the better match, at most `lookahead` key images.
  for (int step = 1; step <= options_.lookahead && position + step <= last; ++step) {
    const KeyComparison ahead = compare_at(position + step);
    if (!Better(ahead, best)) {
      // A frame that verifies against nothing so far may still have passed the next key image quickly.
      if (best.accepted || step > 1) break;
      continue;
    }
    best = ahead;
    best_position = position + step;
  }
  // Not moved on, and nearer `key` than `next_key`: the frame may be behind `key` (a robot that reversed, a
  // hand-held camera swinging back, a relocalization one key image too far). Move back when the previous key
  // image is the better match. Checked only near `key`, where it can be true, to spare a comparison.
  // Checked again on the frames that follow a check that found the previous key image clearly worse only once
  // the frame shares fewer verified matches with the next key image than it did then: until then it has not
  // moved back, and one comparison in 2.4 is spared on most frames near a key image (docs/localize.md).
  const StepBackRuledOut ruled_out = std::exchange(step_back_ruled_out_, {});
  if (options_.step_back && best_position == position && position > 0) {
    const KeyComparison next = position < last ? compare_at(position + 1) : KeyComparison();
    const int v_key = at_key.accepted ? at_key.num_verified : 0;
    const int v_next = next.accepted ? next.num_verified : 0;
    if (3 * v_next < v_key + v_next || v_key == 0) {
      if (v_key > 0 && ruled_out.position == position && v_next >= ruled_out.next_verified) {
        step_back_ruled_out_ = ruled_out;
      } else {
        const KeyComparison behind = compare_at(position - 1);
        if (Better(behind, best)) {
          best = behind;
          best_position = position - 1;
        } else if (v_key > 0 && behind.num_verified < kClearlyWorse * v_key) {
          step_back_ruled_out_ = {position, v_next};
        }
      }
    }
  }
  if (!best.accepted) {
    // Lost against the estimate: the frame may be elsewhere on the route (the robot turned back, skipped
    // ahead, or the estimate was wrong). Look for it over the whole route at once; keep the estimate when
    // that fails too.
    LocalizationResult found = Relocalize(frame, features);
    if (found.status == LocalizationStatus::kRelocalized) return found;
    result.status = LocalizationStatus::kLost;
    result.candidates = std::move(found.candidates);
    ++lost_in_a_row_;
    Describe(result, position, features);
    if (lost_in_a_row_ > options_.max_lost_frames) Reset();
    return result;
  }
  if (SharesLittle(best)) {
    // Accepted, but with much less than neighbouring key images share: the frame may be elsewhere on the
    // route, in view of this key image's scene. Moved when a ranked key image verifies more matches (a
    // relocalization that is not taken leaves nothing behind: the tracked estimate is set below).
    LocalizationResult found = Relocalize(frame, features);
    int found_verified = 0;
    for (const RelocalizationCandidate& c : found.candidates) {
      if (c.accepted) found_verified = std::max(found_verified, c.num_verified);
    }
    if (found.status == LocalizationStatus::kRelocalized && found_verified > best.num_verified) return found;
  }
  lost_in_a_row_ = 0;
  position_ = best_position;
  result.status = LocalizationStatus::kTracking;
  Describe(result, position_, features);
  return result;
}

double Localizer::SharedWithLink(const KeyComparison& comparison, int key_a, int key_b) const {
  for (const Link& link : map_.links) {
    if ((link.from_key == key_a && link.to_key == key_b) || (link.from_key == key_b && link.to_key == key_a)) {
      return link.num_verified > 0 ? static_cast<double>(comparison.num_verified) / link.num_verified : 0.0;
    }
  }
  return 0.0;  // no link between them: not comparable
}

bool Localizer::SharesLittle(const KeyComparison& comparison) const {
  const int reference = link_verified_[comparison.key];
  return reference > 0 && comparison.num_verified < options_.recheck_link_share * reference;
}

LocalizationResult Localizer::Relocalize(const Frame& frame, const ImageFeatures& features) {
  LocalizationResult result;
  const cv::Mat thumbnail = ranking_->method() == RankingMethod::kThumbnails
                                ? ThumbnailDescriptor(frame.gray, options_.ranking.thumbnail_width)
                                : cv::Mat();
  const std::vector<RankedKey> ranked = ranking_->Rank(features, thumbnail);
  KeyComparison best;
  int best_position = -1;
  const int count = std::min<int>(options_.relocalization_candidates, static_cast<int>(ranked.size()));
  for (int i = 0; i < count; ++i) {
    const int position = ranked[i].key;  // the ranking holds the route's key images in route order
    const KeyComparison c = CompareOnce(features, route_[position]);
    result.candidates.push_back(
        {route_[position], ranked[i].score, c.accepted, c.similarity, c.num_verified, c.log10_nfa});
    if (Better(c, best)) {
      best = c;
      best_position = position;
    }
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
  if (position > 0) {
    const KeyComparison before = CompareOnce(features, route_[position - 1]);
    const bool has_next = position + 1 < static_cast<int>(route_.size());
    const KeyComparison after = has_next ? CompareOnce(features, route_[position + 1]) : KeyComparison();
    if (before.accepted && (!has_next || !after.accepted)) {
      position -= 1;
    } else if (before.accepted) {
      const double before_share = SharedWithLink(before, route_[position - 1], route_[position]);
      const double after_share = SharedWithLink(after, route_[position], route_[position + 1]);
      if (before_share > 0 && after_share > 0 ? before_share > after_share : Better(before, after)) position -= 1;
    }
  }
  position_ = position;
  lost_in_a_row_ = 0;
  result.status = LocalizationStatus::kRelocalized;
  Describe(result, position_, features);
  return result;
}

}  // namespace vmap
