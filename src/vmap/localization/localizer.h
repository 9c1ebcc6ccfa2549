#pragma once
// Localization against a visual map (stage 2 of García-Pintos et al. 2023) and the guidance a controller
// needs to servo to the next key image (stages 3-4), one frame at a time.
//
// The map is followed along a route: an ordered list of key images (by default all of them, in the order
// of the teach run). The estimate is a position on that route: the frame is on the segment from `key`
// (the key image last reached) to `next_key` (the one ahead).
//
// - Relocalization (at the start, and whenever tracking fails): every key image of the route is
//   ranked cheaply (KeyImageRanking), the best few are verified like the map's own links (the map's matcher
//   and fundamental-matrix verifier), and the best verified one, with the better of its two neighbours on
//   the route, gives the segment.
// - Tracking: the frame is compared with `key` and `next_key`; when `next_key` is the better match the
//   estimate moves on (and then one key image further is compared too, to move on twice when the robot went
//   fast): the key-image switching of teach-and-repeat systems. Near `key`, the key image before it is
//   compared too, and the estimate moves back when that is the better match. A frame that verifies against
//   none of them is relocalized at once (the robot may have turned back or skipped ahead); when that fails
//   too it is lost and the estimate is kept, and after `max_lost_frames` lost frames in a row it is dropped.
//
// "Better match" is measured by the verified matches (inliers of F) and S, as in the map; "verified" by the
// acceptance rule (acceptance.h: how unlikely the verified matches are by chance and how many against the map's
// links, or counts of verified matches and S). A frame tracked with far fewer verified matches than its key
// image shares with its neighbours is relocalized too, and moved when another key image verifies more.

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/features/matcher.h"
#include "vmap/geometry/camera.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/heading.h"
#include "vmap/geometry/translation_evidence.h"
#include "vmap/localization/acceptance.h"
#include "vmap/localization/key_image_ranking.h"
#include "vmap/localization/key_image_store.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

struct LocalizerOptions {
  // When a comparison accepts the frame at a key image (acceptance.h, docs/localization-acceptance.md).
  // kChance (default): matching and verification succeed, the verified set is unlikely by chance (log10 of its
  // number of false alarms, every comparison a frame can make counted as a test, at most `max_log10_nfa`; 0:
  // what chance would explain less than once over all the comparisons of a frame: the same scene), and it holds
  // at least `min_link_share` times the verified matches of the key image's link with its route neighbour (the
  // smaller of its two links: what two neighbouring key images of this map share, so the bar follows the
  // matcher, the image size and the texture: the same place).
  // kCounts (the earlier rule): at least `min_verified` verified matches and S >= `min_similarity` (S as the map
  // defines it), whatever the matcher and image size.
  // Measured on redkitchen's teach/repeat test (docs/localization-acceptance.md): chance alone 85 frames right
  // and 147 wrong, counts 137 and 8, the defaults below 144 and 7.
  AcceptanceRule acceptance = AcceptanceRule::kChance;
  double max_log10_nfa = 0.0;
  double min_link_share = 0.4;  // 0: chance alone decides (a key image without a link on the route: likewise)
  int min_verified = 20;
  double min_similarity = 0.3;
  // Same scene is not same place. A frame tracked at a key image with fewer verified matches than
  // `recheck_link_share` times those of the key image's link (as above) is also relocalized, and moved to the
  // ranked key image that verifies more matches, if one does: a frame that verifies against a far key image of
  // the same room must not stay there. 0: never (tracking keeps any accepted key image).
  double recheck_link_share = 0.5;
  // Key images compared beyond `next_key` when the frame has passed it (1 or 2: the "next one or two").
  int lookahead = 2;
  // While tracking, also compare the key image before `key` when the frame is nearer `key` than `next_key`
  // (fewer than a third of their verified matches are with `next_key`), and move back when it is the better
  // match: the frame may be behind `key`. A check that finds it clearly worse is repeated on the frames that
  // follow only once their verified matches with `next_key` fall below that frame's (they moved back). Off: the
  // estimate only moves forwards (a robot that never reverses).
  bool step_back = true;
  // Lost frames in a row (each one also failed to relocalize) after which the estimate is dropped: key and
  // next_key then read -1 until a frame is relocalized.
  int max_lost_frames = 5;
  // Best-ranked key images verified when relocalizing.
  int relocalization_candidates = 5;
  RankingOptions ranking;
  // The map's verifier (as map.json records it), except that localization caps its iterations (see
  // MapVerifierOptions): a frame that shares little with a key image must fail fast.
  VerifierOptions verifier;
  SimilarityMode similarity = SimilarityMode::kInlierRatio;
  // Key-image indices to follow, in order (PlanRoute gives one); empty = every key image in map order.
  std::vector<int> route;
  // How the heading to each key image compared is estimated (geometry/heading.h).
  HeadingOptions heading;
  // The map's camera (map.input.camera: intrinsics from the dataset or --camera). With it each comparison
  // also gives the heading in degrees and the relative pose to the key image; without, pixels only.
  std::optional<Camera> camera;
  // When a pose's translation direction is trusted (the map's link_analysis.translation: MapLocalizerOptions).
  TranslationOptions translation;
  // Maps with experiences (map/experiences.h): views of a key image verified besides the key image itself,
  // those with the most tentative matches with the frame (matching is cheap, verification is not). 0: the
  // teach key images only. 2 by default: a frame rarely fits more than the one or two views of its season.
  int experience_candidates = 2;

  // As a localization run records them (its "options"; not the camera, which the map gives) and the flags of
  // `vmap localize`. The verifier, the translation thresholds and the similarity follow the map
  // (MapVerifierOptions, FollowMap): they are recorded, but have no flags here, and the verifier records no
  // early stop (localization verifies each comparison in full).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

enum class LocalizationStatus {
  kTracking,     // verified against the key image(s) of the current estimate
  kRelocalized,  // found by ranking and verifying the whole route (first frame, or the estimate failed)
  kLost,         // verified against no key image; key/next_key keep the last estimate (-1 when there is none)
  // The position is doubted: key/next_key are the belief's best guess along the route, but the evidence does not
  // single it out. A robot must not steer by this frame (LocalizationGuidance, MaySteerBy).
  kUncertain,
};
inline constexpr EnumName<LocalizationStatus> kLocalizationStatusNames[] = {
    {LocalizationStatus::kTracking, "tracking"},
    {LocalizationStatus::kRelocalized, "relocalized"},
    {LocalizationStatus::kLost, "lost"},
    {LocalizationStatus::kUncertain, "uncertain"}};
std::string LocalizationStatusName(LocalizationStatus status);

// The frame compared with one key image.
struct KeyComparison {
  int key = -1;             // key-image index in the map; -1: not compared
  bool matched = false;     // matching and verification succeeded
  bool accepted = false;    // matched, and the acceptance rule holds (LocalizerOptions::acceptance)
  double similarity = 0.0;  // S
  int num_tentative = 0;
  int num_verified = 0;
  cv::Matx33d F = cv::Matx33d::zeros();  // x_key^T F x_frame = 0 (pixels); zero when !matched
  // The heading of the frame against the key image, x in the frame minus x in the key image (px; with a camera
  // also degrees), from all tentative matches (geometry/heading.h): it holds across seasons, where F rarely does.
  HeadingEstimate heading;
  // The verified matches, p0 in the frame and p1 in the compared image (pixels); empty when !matched.
  std::vector<Correspondence> verified;
  // With a camera, on the target comparison of a result (LocalizationResult::to_next, or to_key at the route's
  // end): the key image's camera relative to the frame's, X_key = R X_frame + t, t of unit length
  // (PoseFromFundamental on F and the verified matches, refined by RefineRelativePose and decided again by
  // EnforceCheirality, so t never points backwards). Invalid without a camera, and on the other comparisons:
  // a pose costs as much as a verification, and only the target's guides the robot (Localizer::AddPose).
  RelativePose pose;
  // How well the verified matches determine the pose's translation direction (TranslationSigmaDeg, degrees;
  // NaN without a pose) and whether it is trusted (TranslationKnown with LocalizerOptions::translation).
  double translation_sigma_deg = std::numeric_limits<double>::quiet_NaN();
  bool translation_known = false;
  // log10 of the number of false alarms of the verified set (ChanceOfComparison): how often chance alone
  // would explain it over all the comparisons one frame can make. +infinity when !matched.
  double log10_nfa = std::numeric_limits<double>::infinity();
  // Which image of the key was compared, the best fitting: 0 the teach run's key image, n > 0 the view of
  // experience n (map/experiences.h). With a view, the counts, S, F and log10_nfa are the frame's against the
  // view; the heading is against the key image (the view's heading plus the view's own against the key image);
  // there is no pose (the view's pose to the key image is not known).
  int experience = 0;
};

// A key image the ranking proposed when relocalizing, and how its verification went.
struct RelocalizationCandidate {
  int key = -1;
  double score = 0.0;  // the ranking's score (RankedKey::score)
  bool accepted = false;
  double similarity = 0.0;
  int num_verified = 0;
  double log10_nfa = std::numeric_limits<double>::infinity();  // KeyComparison::log10_nfa
};

struct LocalizationResult {
  int frame_index = 0;
  int source_index = 0;
  double timestamp = -1.0;
  std::string source_name;
  LocalizationStatus status = LocalizationStatus::kLost;
  int key = -1;             // the key image the frame is at (the last reached), -1 when unknown
  int next_key = -1;        // the key image ahead on the route; -1 at the route's end or when unknown
  int route_position = -1;  // index of `key` in the route
  KeyComparison to_key;     // the frame against `key`
  KeyComparison to_next;    // against `next_key`: its F maps the frame to the next key image
  // Heading correction for a controller: the heading of the frame against the target key image (`next_key`,
  // or `key` at the route's end), x in the frame minus x in the key image at the scene both show, in pixels
  // (geometry/heading.h: the densest window of the tentative matches' displacements, or the median of the
  // F-verified ones where F keeps many). Positive: the scene
  // appears to the right of where the key image has it, i.e. the robot points left of the key image's
  // heading and should turn right (clockwise seen from above). NaN when there is no estimate.
  double heading_px = std::numeric_limits<double>::quiet_NaN();
  // The same heading as a bearing in degrees (with the map's camera; NaN without). The relative pose to the
  // target key image is target's `pose` (to_next, or to_key at the route's end).
  double heading_deg = std::numeric_limits<double>::quiet_NaN();
  // The same against `key` (the key image the frame is at); at the route's end the same as heading_px/deg.
  // Each comparison's `heading` holds the estimate's votes and confidence.
  double heading_key_px = std::numeric_limits<double>::quiet_NaN();
  double heading_key_deg = std::numeric_limits<double>::quiet_NaN();
  // Progress along the segment key -> next_key in [0, 1]: v_next / (v_key + v_next) with v the verified
  // matches to each (0 at `key`, 1 at `next_key`, 0.5 where both share as much). NaN when unknown.
  double progress = std::numeric_limits<double>::quiet_NaN();
  // The target's pose has a translation direction to trust. When not (a short baseline to the target, a
  // pure rotation, no camera), the guidance is the heading only: LocalizationGuidance says which.
  bool translation_known = false;
  std::vector<RelocalizationCandidate> candidates;  // relocalization only: those verified, best-ranked first
  int comparisons = 0;   // key images the frame was compared with (some maybe ahead, on workers)
  double seconds = 0.0;  // time spent localizing this frame (features excluded)
  // How sure the localizer is that the frame is at `key` (on the segment key -> next_key): the belief's mass
  // near the chosen key image, 0..1. NaN when not computed.
  double confidence = std::numeric_limits<double>::quiet_NaN();
  // The rank of `key` among the key images the frame was compared with, by the evidence of this frame alone
  // (1: the best match; 2: one other key image matched better...). -1 when unknown (nothing compared).
  int key_rank = -1;
};

class Localizer {
 public:
  // `keys` must hold the features of `map`'s key images computed by `matcher` (LoadKeyImageStore).
  // The map, the store and the matcher must outlive the localizer.
  Localizer(const VisualMap& map, const KeyImageStore& keys, const Matcher& matcher, LocalizerOptions options);
  ~Localizer();
  Localizer(const Localizer&) = delete;
  Localizer& operator=(const Localizer&) = delete;

  // Localizes the next frame of the stream. `features` come from the map's matcher on frame.gray (they may
  // be extracted on another thread: see LocalizeSequence). `ahead` may hold comparisons of this frame that
  // were already made (Compare, on another thread, with the LikelyKeys of an earlier state): they are used
  // instead of comparing again, which gives the same result.
  LocalizationResult Localize(const Frame& frame, const ImageFeatures& features, std::vector<KeyComparison> ahead = {});

  // The key images the next frame will most likely be compared with: `key` and `next_key` of the current
  // estimate (none without an estimate).
  std::vector<int> LikelyKeys() const;
  // The frame's features against key image `key`, as Localize compares them. Thread-safe (const, and the
  // matcher's Match and the verifier are), so frames can be compared ahead on other threads.
  KeyComparison Compare(const ImageFeatures& features, int key) const;

  // Adds the relative pose, its translation sigma and whether the translation is known to a comparison of
  // the teach key image (experience 0) that matched, when the options have a camera. Localize does it for the
  // target comparison of each result.
  void AddPose(KeyComparison& comparison) const;

  // Forgets the estimate: the next frame is relocalized.
  void Reset();
  bool has_estimate() const { return position_ >= 0; }
  const std::vector<int>& route() const { return route_; }
  RankingMethod ranking_method() const { return ranking_->method(); }

 private:
  // The frame against one image of key image `key` (the key image itself or a view), from their matches.
  KeyComparison CompareImage(const ImageFeatures& features, const ImageFeatures& image, const TentativeMatches& matches,
                             int key) const;
  // Each key image is compared with a frame at most once per Localize call.
  KeyComparison CompareOnce(const ImageFeatures& features, int key);
  LocalizationResult Track(const Frame& frame, const ImageFeatures& features);
  LocalizationResult Relocalize(const Frame& frame, const ImageFeatures& features);
  void Describe(LocalizationResult& result, int position, const ImageFeatures& features);

  // The frame's verified matches with key_a over those of the map's link between key_a and key_b (0 when
  // they have no link).
  double SharedWithLink(const KeyComparison& comparison, int key_a, int key_b) const;
  // A tracked comparison shares less with its key image than the map's links do (recheck_link_share).
  bool SharesLittle(const KeyComparison& comparison) const;

  const VisualMap& map_;
  const KeyImageStore& keys_;
  const Matcher& matcher_;
  LocalizerOptions options_;
  std::vector<int> route_;
  std::vector<int> route_position_of_key_;  // -1 for key images off the route
  // Per key image: the verified matches of its link with a route neighbour, the smaller of the two; 0 when it
  // has no verified link on the route (the comparisons against the map's links are then skipped).
  std::vector<int> link_verified_;
  std::unique_ptr<KeyImageRanking> ranking_;
  int position_ = -1;  // route position of `key`; -1: no estimate
  int lost_in_a_row_ = 0;
  // The step back last ruled out (Track): at route position `position`, on the frame before this one, with the
  // frame's verified matches with the next key image at that last check. position -1: none.
  struct StepBackRuledOut {
    int position = -1;
    int next_verified = 0;
  } step_back_ruled_out_;
  struct Memo {
    KeyComparison comparison;
    bool used = false;  // counted in LocalizationResult::comparisons
  };
  std::vector<Memo> comparisons_;  // of the frame being localized
};

// The key images on either side of position `source_index` of the map's input (KeyImage::source_index):
// the last key image at or before it and the first at or after it; -1 where there is none. A frame of the
// teach run's path between two key images is rightly localized at either (the bracket test of
// docs/measurements/localization.md).
std::pair<int, int> KeysAround(const VisualMap& map, int source_index);

// The verifier the map records (options.verifier in map.json), bounded: a comparison asks "is the frame at this key
// image?", not for the best F, so its cost must not grow with the matches or fall to MAGSAC's iteration cap.
// - Scored matches (XFeat, ALIKED) of a map verified by MAGSAC: vmap's MAGSAC++ (within a seed change of
//   OpenCV's) with at most `max_iterations` samples drawn from the `loop_points` best-scored matches, its model
//   refined on all of them (VerifierOptions::loop_points): thousands of XFeat matches cost what 512 do.
// - Matches without scores (ORB): the map's verifier with at most 5000 iterations. Why capped: a frame compared
//   with a key image it barely overlaps has a low inlier ratio, for which MAGSAC runs to the map's 100,000
//   iterations (about a second); such a pair fails the acceptance test anyway.
// Measured with bench/verify_bench (docs/matchers.md, "Speed of verification").
VerifierOptions MapVerifierOptions(const VerifierOptions& recorded, int max_iterations = 1000, int loop_points = 512);

// What a controller may use of a result: "heading and translation", "heading only: translation unknown"
// (a pose whose translation direction is not to be trusted), "heading only: no pose" (no camera, or no pose
// to the target), or nothing to steer by: "none: lost" (kLost), "none: position uncertain" (kUncertain: the
// key images are a guess), "none" (no heading). Every value that starts with "none" means: do not steer by
// this frame.
std::string LocalizationGuidance(const LocalizationResult& result);
// Whether a controller may steer by the result: tracking or relocalized, with a heading to the target
// (LocalizationGuidance does not start with "none").
bool MaySteerBy(const LocalizationResult& result);

}  // namespace vmap
