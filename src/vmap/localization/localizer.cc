#include "vmap/localization/localizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/stopwatch.h"
#include "vmap/features/camera_mask.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/localization/route.h"
#include "vmap/sources/odometry.h"

namespace vmap {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// What the map's camera gave a result: bearings and poses, gone where the camera does not describe the frame.
void ForgetCamera(KeyComparison& comparison) {
  comparison.heading.deg = kNaN;
  comparison.pose = RelativePose{};
  comparison.translation_sigma_deg = kNaN;
  comparison.translation_known = false;
}
void ForgetCamera(LocalizationResult& result) {
  ForgetCamera(result.to_key);
  ForgetCamera(result.to_next);
  result.heading_deg = result.heading_key_deg = kNaN;
  result.translation_known = false;
}

// The link's verified matches pass chance as a comparison's must (acceptance.h), one test: the two key images share a
// scene. Without its matches in memory (a map loaded without them) it is taken to.
bool OfOneScene(const Link& link, cv::Size from_size, cv::Size to_size, double max_log10_nfa) {
  if (link.correspondences.empty()) return true;
  PairComparison pair;
  pair.matched = true;
  pair.num_tentative = link.num_tentative;
  pair.num_verified = link.num_verified;
  pair.F = link.F;
  pair.correspondences = link.correspondences;
  return ChanceOfComparison(pair, from_size, to_size, 1).log10_nfa <= max_log10_nfa;
}

// The options of the map's ORB matcher, for a matcher that changes one of them (guided, window and lost-frame
// matching): the rest as the key images were extracted.
MatcherOptions MapOrbOptions(const Matcher& map_matcher) {
  MatcherOptions options;
  options.type = OrbMatcherOptions::kModelName;
  options.model(options.type).FromJson(nlohmann::json::parse(map_matcher.DescribeOptionsJson()), "the map's matcher");
  return options;
}

}  // namespace

Localizer::Localizer(const VisualMap& map, const KeyImageStore& keys, const Matcher& matcher, LocalizerOptions options)
    : map_(map),
      keys_(keys),
      matcher_(matcher),
      options_(std::move(options)),
      comparer_(keys, matcher, options_),
      continuity_(options_),
      belief_(std::max<int>(1, options_.route.empty() ? map.key_images.size() : options_.route.size()),
              options_.belief),
      evidence_belief_(belief_),
      lagging_start_(options_.lagging_tracker_frames, options_.lagging_start_frames),
      stall_(options_.stalled_tracker_frames, options_.unsettled_stalled_tracker_frames),
      comparisons_([this](const ImageFeatures& features,
                          int key) { return Compare(features, key, FarComparisonIterations(key)); },
                   options_.comparison_threads - 1) {
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
  CheckStartKey(map_, options_);
  if (options_.start_key >= 0) start_position_ = route_position_of_key_[options_.start_key];
  link_verified_.assign(num_keys, 0);
  scene_link_after_.assign(route_.size(), false);
  std::vector<std::optional<SharedByKeys>> link_after(route_.size());
  for (const Link& link : map_.links) {
    const int a = link.from_key, b = link.to_key;
    if (a < 0 || b < 0 || a >= num_keys || b >= num_keys || route_position_of_key_[a] < 0 ||
        route_position_of_key_[b] < 0 || std::abs(route_position_of_key_[a] - route_position_of_key_[b]) != 1 ||
        !link.has_fundamental || link.num_verified <= 0) {
      continue;
    }
    // A link chance refuses joins two places, not one scene (a --tau 1 map of unrelated places). Its verified count
    // still bounds the link share: what two unrelated places verify by chance is a floor a frame must pass (with XFeat,
    // whose chance model passes at most wrong key images, dropping it cost michigan 653 -> 581, 5 frames far).
    const int before = std::min(route_position_of_key_[a], route_position_of_key_[b]);
    scene_link_after_[before] =
        OfOneScene(link, keys_.features[a]->image_size(), keys_.features[b]->image_size(), options_.max_log10_nfa);
    link_after[before] = SharedByKeys{link.similarity, link.num_verified};
  }
  // The map's links, and the acceptance's reference: the same, or on a map denser than link_share_tau spaces key
  // images, the links a map of that tau would hold, each key image compared as a frame is (the teach key image alone).
  const auto compare = [&](int p, int q) -> std::optional<SharedByKeys> {
    const ImageFeatures& from = *keys_.features[route_[p]];
    const ImageFeatures& to = *keys_.features[route_[q]];
    const KeyComparison c = comparer_.CompareImage(from, to, matcher_.Match(from, to), route_[q]);
    if (!c.matched) return std::nullopt;
    return SharedByKeys{c.similarity, c.num_verified};
  };
  const std::vector<int> links = LinkShareReference(link_after, compare, kInfinity, 1);
  const bool denser = options_.link_share_tau > 0.0 && options_.map_tau > options_.link_share_tau;
  const std::vector<int> spaced = denser ? LinkShareReference(link_after, compare, options_.link_share_tau,
                                                              kLinkShareReach, options_.comparison_threads)
                                         : links;
  std::vector<int> share_reference(num_keys, 0);
  for (size_t p = 0; p < route_.size(); ++p) {
    link_verified_[route_[p]] = links[p];
    share_reference[route_[p]] = spaced[p];
  }
  comparer_.SetShareReference(std::move(share_reference));
  // Only the route's key images take part in the ranking.
  std::vector<std::shared_ptr<const ImageFeatures>> features;
  std::vector<cv::Mat> thumbnails;
  for (int k : route_) {
    features.push_back(keys_.features[k]);
    thumbnails.push_back(keys_.thumbnails[k]);
  }
  ranking_ = std::make_unique<KeyImageRanking>(features, thumbnails, options_.ranking);
  const cv::Mat descriptors = keys_.features.front()->descriptors();
  const bool binary = !descriptors.empty() && descriptors.depth() == CV_8U;
  evidence_ = binary                      ? BinaryDescriptorEvidence()
              : options_.rank_by_standout ? FloatDescriptorEvidence()
                                          : FloatDescriptorEvidenceByRank();
  if (!options_.rank_evidence) evidence_.rank_alone.clear();
  start_checked_over_route_ = binary;
  nfa_ranks_key_images_ = binary;
  heading_accepts_ = binary;
  binary_descriptors_ = binary;
  if (options_.guided_matching && matcher_.name() == OrbMatcherOptions::kModelName) {
    MatcherOptions guided = MapOrbOptions(matcher_);
    guided.Of<OrbMatcherOptions>().cross_check = false;
    guided_matcher_ = WithCameraMaskOf(matcher_, CreateMatcher(guided));
    if (options_.window_matching && (options_.window_fast_threshold > 0 || options_.window_features > 0)) {
      OrbMatcherOptions& orb = guided.Of<OrbMatcherOptions>();
      if (options_.window_fast_threshold > 0) orb.fast_threshold = options_.window_fast_threshold;
      if (options_.window_features > 0) orb.num_features = options_.window_features;
      window_matcher_ = WithCameraMaskOf(matcher_, CreateMatcher(guided));
    }
  }
  if (options_.lost_frame_features > 0 && matcher_.name() == OrbMatcherOptions::kModelName &&
      !keys_.directory.empty()) {
    MatcherOptions more = MapOrbOptions(matcher_);
    more.Of<OrbMatcherOptions>().num_features = options_.lost_frame_features;
    lost_frame_matcher_ =
        std::make_unique<LostFrameMatcher>(WithCameraMaskOf(matcher_, CreateMatcher(more)), map_, keys_.directory);
  }
  // The rules that step a frame on to the next key image ask whether it stands still (StillSinceFrameBefore), and so
  // does the question of a held tracker (a stop holds it).
  const bool steps_on_next =
      (lost_frame_matcher_ && options_.lost_frame_next_heading_ratio > 0.0) ||
      (heading_accepts_ && (options_.step_on_where_evidence_agrees || options_.step_on_after_lost_frames)) ||
      (!binary && options_.stalled_tracker_frames > 0);
  // So do the questions of a frame that may have been carried off (SceneChangedSinceFrameBefore).
  const bool asks_scene_change = !binary && options_.scene_change_log10_nfa < 0.0;
  keeps_features_before_ = (steps_on_next && options_.still_frame_share > 0.0) || asks_scene_change;
  std::vector<int> route_source_indices;
  std::vector<double> route_timestamps;
  for (const int k : route_) {
    route_source_indices.push_back(map_.key_images[k].source_index);
    route_timestamps.push_back(map_.key_images[k].timestamp);
  }
  pace_ = MotionPace(route_source_indices, route_timestamps, options_.belief.motion_steps_per_frame);
  Reset();  // at the start key image, when there is one
}

Localizer::~Localizer() = default;

bool Localizer::PaceByTeachOdometry(const std::vector<OdometrySample>& teach_odometry) {
  std::vector<double> route_distances;
  if (!teach_odometry.empty()) {
    const OdometryTrack track(teach_odometry);
    for (const int k : route_) {
      const double t = map_.key_images[k].timestamp;
      route_distances.push_back(t >= 0.0 ? track.DistanceAt(t) : std::numeric_limits<double>::quiet_NaN());
    }
  }
  pace_.SetTeachDistances(route_distances);
  return pace_.by_distance();
}

void CheckStartKey(const VisualMap& map, const LocalizerOptions& options) {
  const int key = options.start_key;
  if (key < 0) return;
  CheckKeyImageOption(map, key, "start_key");
  if (!options.route.empty() && std::find(options.route.begin(), options.route.end(), key) == options.route.end()) {
    throw OptionError("start_key", fmt::format("{} is not on the route (key images {} to {})", key,
                                               options.route.front(), options.route.back()));
  }
}

void Localizer::Reset() {
  belief_.Reset();
  evidence_belief_.Reset();
  if (start_position_ >= 0) belief_.Start(start_position_, options_.start_mass);
  start_unconfirmed_ = start_position_ >= 0 && options_.start_is_hint;
  pointed_ = pointed_before_ = -1;
  start_question_.reset();
  confident_peak_ = confident_peak_before_ = -1;
  rival_place_ = -1;
  rival_frames_left_ = 0;
  stall_.Reset();
  lagging_start_.Reset();
  pace_.Reset();
  lookahead_ = options_.lookahead;
  placed_in_a_row_ = 0;
  position_ = start_position_;
  lost_in_a_row_ = 0;
  placed_before_ = steered_before_ = moved_back_to_ = -1;
  features_before_.clear();
  ranking_first_before_ = heading_mode_before_ = -1;
  dropped_position_ = -1;
  frames_since_drop_ = 0;
  step_back_ruled_out_ = {};
  continuity_.Reset();
}

LocalizationResult Localizer::Localize(const Frame& frame, const ImageFeatures& features,
                                       std::vector<KeyComparison> ahead) {
  const auto start = std::chrono::steady_clock::now();
  // The comparisons made meanwhile read `features`: those not taken are done with before the frame is.
  struct FinishComparisons {
    FrameComparisons& comparisons;
    ~FinishComparisons() { comparisons.Finish(); }
  } finish_comparisons{comparisons_};
  frame_start_position_ = position_;
  const int motion_steps = pace_.Steps(frame.source_index, frame.timestamp, frame.odometry);
  lookahead_ = options_.lookahead_by_pace ? pace_.Lookahead(position_, options_.lookahead) : options_.lookahead;
  // The comparisons made ahead verified in full: those the frame verifies with fewer iterations are made again.
  ahead.erase(std::remove_if(ahead.begin(), ahead.end(),
                             [&](const KeyComparison& c) { return FarComparisonIterations(c.key) > 0; }),
              ahead.end());
  comparisons_.Begin(std::move(ahead));
  ranked_.clear();
  bucket_of_position_.clear();
  blind_ = features.num_features() < options_.verifier.min_matches;
  belief_.Predict(motion_steps);
  if (start_unconfirmed_) evidence_belief_.Predict(motion_steps);
  // Guided matching asks where the estimate was dropped for max_lost_frames frames (guided_while_lost).
  if (dropped_position_ >= 0 && ++frames_since_drop_ > options_.max_lost_frames) dropped_position_ = -1;
  belief_confident_ = SinglesOut(belief_.Peak());
  confident_peak_before_ = std::exchange(confident_peak_, belief_confident_ ? belief_.Peak() : -1);
  steps_on_ = 0;
  stepped_back_from_ = -1;
  pointed_before_ = std::exchange(pointed_, -1);
  LocalizationResult result = has_estimate() ? Track(frame, features) : Reacquire(frame, features);
  CompareRivalPlace(result, features);
  // A hint is checked: the frame's evidence over the whole route weighs where the run is.
  if (start_unconfirmed_ && start_checked_over_route_) CompareBestRanked(frame, features);
  QuestionStalledTracker(result, frame, features);
  Believe(result, frame, features);
  DoubtStalledTracker(result);
  stall_.Count(result.route_position, IsPlaced(result.status), HeldWhereNextSeesNothing(result), position_,
               placed_in_a_row_);
  lagging_start_.Remember(position_);
  RememberWhereDriven(frame_start_position_);
  RememberRivalPlace(result);
  if (IsPlaced(result.status)) {
    dropped_position_ = -1;  // steered by again: the drop is behind
  }
  // A frame the rules above withheld and a later one placed again is not withheld.
  if (result.status != LocalizationStatus::kUncertain) result.withheld_by = Withholding::kNone;
  result.comparisons = static_cast<int>(comparisons_.size());
  if (result.key >= 0 && result.to_key.key == result.key) {
    result.key_rank = 1 + static_cast<int>(std::count_if(comparisons_.begin(), comparisons_.end(), [&](const Memo& m) {
                        return m.comparison.key != result.key && FitsBetter(m.comparison, result.to_key);
                      }));
  }
  // A guess must not be tracked from: after an uncertain frame that moved the estimate more than kNear (a
  // relocalization the belief doubts, such as one chance refused), the continuity would accept the next frame at the
  // guessed place on the guess's own heading there; the frames after it confirm or refute the place on evidence chance
  // weighs (docs/measurements/localization-conditions.md, "A guess chance refused is not tracked from").
  continuity_.Remember(comparisons_, result.status == LocalizationStatus::kUncertain && position_ >= 0 &&
                                         frame_start_position_ >= 0 &&
                                         std::abs(position_ - frame_start_position_) > kNear);
  placed_before_ = IsPlaced(result.status) ? result.route_position : -1;
  placed_in_a_row_ = IsPlaced(result.status) ? placed_in_a_row_ + 1 : 0;
  RememberMoveBack(result);
  // Kept as the matcher serializes them: features are polymorphic and the caller's go with the frame; only while the
  // run has an estimate, since the next frame asks whether it stands still only when tracked from it (after a frame
  // placed there, or lost there).
  if (keeps_features_before_) features_before_ = has_estimate() ? matcher_.SerializeFeatures(features) : "";
  ranking_first_before_ = RankingFirst();
  heading_mode_before_ = HeadingMode();
  result.motion_steps = motion_steps;
  result.frame_index = frame.index;
  result.source_index = frame.source_index;
  result.timestamp = frame.timestamp;
  result.source_name = frame.source_name;
  // A frame of another shape than the teach run's frames was stretched to the map's size: the map's camera does not
  // describe it, so its headings are in pixels only and it has no pose (as with --resize to another size).
  if (options_.camera && AspectRatiosDiffer(frame.native_size, map_.input.native_size)) {
    if (!warned_stretched_) {
      spdlog::warn(
          "frame {} is {}x{}, another shape than the map's frames ({}x{}): stretched to the map's size, it "
          "gets headings in pixels only and no relative poses (the map's camera does not describe it)",
          frame.source_name, frame.native_size.width, frame.native_size.height, map_.input.native_size.width,
          map_.input.native_size.height);
      warned_stretched_ = true;
    }
    ForgetCamera(result);
  }
  comparisons_.Finish();
  result.seconds = SecondsSince(start);
  return result;
}

std::vector<int> Localizer::LikelyKeys() const {
  if (!has_estimate()) return {};
  std::vector<int> keys = {route_[position_]};
  if (position_ + 1 < static_cast<int>(route_.size())) keys.push_back(route_[position_ + 1]);
  return keys;
}

// Fills key, next_key, their comparisons, heading and progress for the estimate at route `position`.
void Localizer::Describe(LocalizationResult& result, int position, const ImageFeatures& features) {
  result.route_position = position;
  result.key = route_[position];
  result.to_key = comparisons_.Once(features, result.key);
  const bool at_end = position + 1 >= static_cast<int>(route_.size());
  result.next_key = at_end ? -1 : route_[position + 1];
  result.to_next = at_end ? KeyComparison() : comparisons_.Once(features, result.next_key);
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

}  // namespace vmap
