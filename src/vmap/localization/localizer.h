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
// - Tracking: the frame is compared with `key` and `next_key`; when `next_key` is the better match the estimate moves
//   on (and then one key image further is compared too, to move on twice when the robot went fast): the key-image
//   switching of teach-and-repeat systems. Near `key`, the key image before it is compared too, and the estimate moves
//   back when that is the better match. A frame that verifies against none of them is relocalized at once (the robot
//   may have turned back or skipped ahead); when that fails too it is lost and the estimate is kept, and after
//   `max_lost_frames` lost frames in a row it is dropped.
//
// "Better match" is measured by the verified matches (inliers of F) and S, as in the map; "verified" by the
// acceptance rule (acceptance.h: how unlikely the verified matches are by chance and how many against the map's
// links, or counts of verified matches and S). A frame tracked with far fewer verified matches than its key
// image shares with its neighbours is relocalized too, and moved when another key image verifies more.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/localization/frame_comparisons.h"
#include "vmap/localization/heading_continuity.h"
#include "vmap/localization/key_bracket.h"
#include "vmap/localization/key_comparison.h"
#include "vmap/localization/key_image_comparer.h"
#include "vmap/localization/key_image_ranking.h"
#include "vmap/localization/key_image_store.h"
#include "vmap/localization/lagging_start.h"
#include "vmap/localization/link_share_reference.h"
#include "vmap/localization/localization_result.h"
#include "vmap/localization/localizer_options.h"
#include "vmap/localization/lost_frame_matcher.h"
#include "vmap/localization/map_verifier_options.h"
#include "vmap/localization/motion_pace.h"
#include "vmap/localization/route_belief.h"
#include "vmap/localization/route_evidence.h"
#include "vmap/localization/stalled_tracker.h"
#include "vmap/map/visual_map.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// Throws InputError when LocalizerOptions::start_key is not a key image of `map` on the options' route.
void CheckStartKey(const VisualMap& map, const LocalizerOptions& options);

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
  // were already made (Compare, on another thread, with the LikelyKeys of an earlier state): each is used where
  // the frame asks for its key image instead of comparing again, which gives the same result, bit for bit.
  LocalizationResult Localize(const Frame& frame, const ImageFeatures& features, std::vector<KeyComparison> ahead = {});

  // The key images the next frame will most likely be compared with: `key` and `next_key` of the current
  // estimate (none without an estimate).
  std::vector<int> LikelyKeys() const;
  // The frame's features against key image `key`, as Localize compares them (KeyImageComparer), its verifier's
  // iterations at most `max_iterations` where above 0 (as Localize verifies those away from the tracker:
  // FarComparisonIterations). Thread-safe, so frames can be compared ahead on other threads.
  KeyComparison Compare(const ImageFeatures& features, int key, int max_iterations = 0) const {
    return comparer_.Compare(features, key, max_iterations);
  }

  // Adds the relative pose, its translation sigma and whether the translation is known to a comparison of
  // the teach key image (experience 0) that matched, when the options have a camera. Localize does it for the
  // target comparison of each result.
  void AddPose(KeyComparison& comparison) const { comparer_.AddPose(comparison); }

  // The teach run's odometry (its samples on the key images' clock): where a frame has odometry too (Frame::odometry),
  // the motion model moves by the distance driven since the frame before against the teach odometry's distance
  // between the route's key images (localization/motion_pace.h: TeachMetresPerPosition). Empty, covering fewer than two
  // of the route's key images, or not along one direction: the pace by time or index, as without it (returns false).
  bool PaceByTeachOdometry(const std::vector<OdometrySample>& teach_odometry);

  // Forgets the estimate: the next frame is relocalized, or starts again at LocalizerOptions::start_key.
  void Reset();
  bool has_estimate() const { return position_ >= 0; }
  const std::vector<int>& route() const { return route_; }
  RankingMethod ranking_method() const { return ranking_->method(); }

 private:
  // The verifier's iterations for the frame's comparison with key image `key` (LocalizerOptions::
  // far_comparison_iterations): the cap for a key image away from the tracker's, 0 (the verifier's own) otherwise.
  int FarComparisonIterations(int key) const;
  // The frame's comparisons with the key images at route `positions` (those on the route), which it is about to make,
  // in that order: made meanwhile on the other comparison threads (FrameComparisons::Meanwhile).
  void CompareMeanwhile(const ImageFeatures& features, const std::vector<int>& positions);
  // Guided matching (LocalizerOptions::guided_matching): the frame matched again with guided_matcher_ at route
  // `position` and the `lookahead` after it (guided_lookahead; else the one after it), the belief singling out that
  // place, each only where its first comparison verified at least the link share (min_link_share; chance alone refused
  // it). Returns the route position of the best accepted comparison (guided_lookahead: by one measure common to them),
  // which replaces the frame's memo of that key image (its first comparison weighed into the belief first); -1 when
  // none is accepted or guided matching does not apply.
  // `whatever_the_belief`: asked though the belief does not single the place out (guided_while_lost).
  int TrackGuided(const Frame& frame, const ImageFeatures& features, int position, bool whatever_the_belief = false);
  // The ranking's best key images (CompareBestRanked) whose first comparison chance refused and the link share did
  // not, compared again by `again` (nullopt: ask no further); each second comparison chance accepts replaces its key
  // image's memo (the first one's evidence weighed first). Returns whether any was accepted. Chance decides alone, as
  // for every comparison made again: the counts rule would take the extra matches as evidence.
  bool CompareBestRankedAgain(const Frame& frame, const ImageFeatures& features,
                              const std::function<std::optional<KeyComparison>(int key)>& again);
  // Guided relocalization (LocalizerOptions::guided_relocalization): CompareBestRankedAgain with the frame matched
  // again by guided_matcher_.
  bool GuideRelocalization(const Frame& frame, const ImageFeatures& features);
  // What a lost frame's second look found: nothing, a comparison accepted, or one accepted by a heading that stands
  // out less (AcceptLostFrameByHeading), whose frame is placed, not steered by.
  enum class SecondLook { kNothing, kAccepted, kPlacedOnly };
  // A lost frame compared again with more features (LocalizerOptions::lost_frame_features): CompareBestRankedAgain
  // with the frame's and the key image's features extracted again by lost_frame_matcher_.
  SecondLook CompareLostFrameAgain(const Frame& frame, const ImageFeatures& features);
  // Where chance accepts none of them, the comparison with more features whose heading mode stands out against the
  // others made so (LocalizerOptions::lost_frame_heading) is accepted as by HeadingStandsOut (kAccepted).
  // Below lost_frame_heading_rival_ratio, down to lost_frame_heading_near_ratio, only from kNear behind the estimate
  // the frame starts from to JumpReach ahead of it (kPlacedOnly); down to lost_frame_next_heading_ratio, only at the
  // key image the frame before was placed at or the next, and never the next for a frame that stands still
  // (kPlacedOnly). Whatever the ratio, never beyond kNear of the estimate for a frame that stands still.
  SecondLook AcceptLostFrameByHeading(const std::vector<KeyComparison>& compared, const ImageFeatures& features);
  // The frame stands still against the frame before (StandsStill); false when the frame before's features were not
  // kept.
  bool StillSinceFrameBefore(const ImageFeatures& features) const;
  // The frame does not share the frame before's scene as consecutive frames of a moving robot do (its comparison with
  // it above scene_change_log10_nfa); false when the frame before's features were not kept, or on binary descriptors.
  bool SceneChangedSinceFrameBefore(const ImageFeatures& features) const;
  // A lost frame steps on where its evidence agrees (LocalizerOptions::step_on_where_evidence_agrees): whether the
  // frame's ranking (ranked by its relocalization) and its comparisons' heading modes each single out the key image
  // at route `position + 1`, the tracker's next.
  bool EvidenceAgreesOnNext(int position) const;
  // A frame placed where its ranking and its heading agree is not steered by: `placed` without its heading.
  static LocalizationResult PlacedByAgreement(LocalizationResult placed);
  // The route position the frame's ranking (ranked by its relocalization) puts first, strictly; -1: none (not ranked,
  // or a tie).
  int RankingFirst() const;
  // The route position of the key image whose comparison holds the most heading votes, strictly; -1: none.
  int HeadingMode() const;
  LocalizationResult Track(const Frame& frame, const ImageFeatures& features);
  // The frame tracked at route `position`, the estimate having been at `from`.
  LocalizationResult TrackedAt(LocalizationResult result, int from, int position, const ImageFeatures& features);
  // Relocalization (localizer_relocalize.cc): the frame compared with the best-ranked key images, placed on the segment
  // before or after the best accepted one.
  LocalizationResult Relocalize(const Frame& frame, const ImageFeatures& features);
  // Without an estimate: relocalized, and when nothing verifies, matched guided where the estimate was dropped
  // (LocalizerOptions::guided_while_lost).
  LocalizationResult Reacquire(const Frame& frame, const ImageFeatures& features);
  void Describe(LocalizationResult& result, int position, const ImageFeatures& features);
  // The belief's rules moving the tracker on the frame's own evidence: the result becomes the frame described at route
  // `position` with `status` (its relocalization candidates kept), and the tracker goes on from there.
  void MoveTrackerTo(LocalizationResult& result, int position, LocalizationStatus status,
                     const ImageFeatures& features);
  // The belief's step (localizer_belief.cc): weighs the evidence of every comparison of the frame, then sets the
  // result's confidence and, when the belief does not single out the tracked position, the status kUncertain.
  void Believe(LocalizationResult& result, const Frame& frame, const ImageFeatures& features);
  void WeighComparisons();
  // The belief, and while the start is unconfirmed the frames' evidence's own (evidence_belief_), weighed at route
  // `position` by `log_ratio`, and normalized once the frame's weights are in.
  void WeighBeliefs(int position, double log_ratio);
  void NormalizeBeliefs();
  // Where the frame was ranked and the evidence model weighs the ranking: weighs every route position by its key
  // image's bucket in the ranking (once a frame), and the comparisons already weighed without it by what their bucket
  // changes. Returns whether it weighed anything.
  bool WeighRanking();
  // The frame's ranking weighs the belief before the belief's rules move the tracker (XFeat's:
  // EvidenceModel::ranking_moves_own_frame); ORB's weighs it after them.
  bool RankingMovesOwnFrame() const { return !evidence_.rank_alone.empty() && evidence_.ranking_moves_own_frame; }
  // A frame the tracker moved on (it is tracked at the key image it is nearest) goes back one key image when the
  // belief says so. The belief's positions are segments: a frame at key image k is on segment k - 1 or k. One key
  // image on, to k: back when the belief holds more on segment k - 2 than on segment k (two key images that look alike,
  // one teach frame apart or across seasons, are not told apart by one frame's matches; the frames before it and the
  // motion prior are). Two on: back when it holds more on segment k - 1 than on k (one key image a frame is likelier).
  // The key image passed need not verify (LocalizerOptions::hold_unearned_step_on) where the map's link to the one
  // reached is of one scene: the frame then stays tracking on the segment before the key image reached, which verified.
  void SettleStepOn(LocalizationResult& result, const ImageFeatures& features);
  // A step back needs the belief (LocalizerOptions::step_back_needs_belief): a frame the tracker moved back from key
  // image l to k (at most kNear key images; stepped_back_from_) returns to l when the belief, after the frame's
  // evidence, holds more on segment l (past l) than on segment k - 1 (before k) and than a flat belief, and
  // min_confidence within kNear of l, and l verifies; not when k verifies beyond the evidence's bound. The mirror of
  // SettleStepOn.
  void SettleStepBack(LocalizationResult& result, const ImageFeatures& features);
  // The mirror of SettleStepOn (LocalizerOptions::step_on_by_belief): a frame tracked at key image k moves on to k + 1
  // when the belief holds more on the segments from k + 1 on than on segments k and k - 1 (the frame is past k + 1
  // more likely than before it) and k + 1 verifies; again for k + 2, up to `lookahead` key images. Only where the
  // belief singled out a place before the frame's evidence (belief_confident_).
  void StepOnByBelief(LocalizationResult& result, const ImageFeatures& features);
  // The belief singles out route `position` (not only holds min_confidence near it: also far more than a flat
  // belief would).
  bool SinglesOut(int position) const { return SinglesOut(belief_, position); }
  bool SinglesOut(const RouteBelief& belief, int position) const;
  // The start is a hint (LocalizerOptions::start_is_hint): the frames' evidence alone (evidence_belief_) singles out
  // a place more than kNear route positions from `position` and holds less than min_confidence near it.
  bool EvidencePointsAway(int position) const;
  // The start needs the frames' evidence (LocalizerOptions::start_needs_evidence): while the start is unconfirmed,
  // evidence_belief_ holds less within kNear of `position` than a flat belief would, on a route where those positions
  // hold at most half of it.
  bool EvidenceWeighsAgainst(int position) const;
  // While the start is unconfirmed, with float descriptors, for a frame accepted at its place (else nullopt): the
  // frame's ranking, made now where the frame was not ranked, when it then weighs evidence_belief_
  // (LocalizerOptions::start_evidence_ranks_frame; localizer_start_place.cc).
  std::optional<std::vector<RankedKey>> RankForUnconfirmedStart(const LocalizationResult& result, const Frame& frame,
                                                                const ImageFeatures& features);
  // For such a frame (LocalizerOptions::start_place_stands_out): a key image more than kNear from the frame's place
  // (one it compared, or the best of `ranked` that is that far, compared now without weighing the belief) verified at
  // least as many matches as its accepted key images, or weighs at least as much by the evidence model: the frame
  // cannot tell its place from a far one.
  bool StartPlaceTiesFar(const LocalizationResult& result, const ImageFeatures& features,
                         const std::vector<RankedKey>& ranked);
  // Weighs start_question_ into both beliefs once the frame is decided (LocalizerOptions::start_question_weighs).
  void WeighStartQuestion();
  // evidence_belief_ alone weighed by the frame's ranking `ranked`, as WeighRanking weighs both beliefs for a frame
  // ranked before its moves (localizer_start_place.cc).
  void WeighEvidenceByRanking(const std::vector<RankedKey>& ranked);
  // A frame relocalized more than kNear route positions from steered_before_, at key images that verify by little
  // beyond chance (LocalizerOptions::doubt_relocalization_on_little_chance; localizer_little_chance.cc).
  bool PlacedAwayOnLittleChance(const LocalizationResult& result) const;
  bool StartAwayLacksBelief(const LocalizationResult& result) const;
  // A tracker held at one key image (LocalizerOptions::stalled_tracker_frames; localizer_stalled_tracker.cc): the
  // frame, tracked there as the frames before it were (stall_), has its next key image verify nothing beyond a little
  // chance. A frame that stands still against the frame before (a robot that stopped) neither adds to the hold nor is
  // asked.
  bool HeldWhereNextSeesNothing(const LocalizationResult& result) const;
  // The frame that makes the tracker held stalled_tracker_frames frames in a row is compared with the route's
  // best-ranked key images: their evidence and the ranking's weigh the belief, which the rules after it read.
  void QuestionStalledTracker(const LocalizationResult& result, const Frame& frame, const ImageFeatures& features);
  // The questioned frame is steered by only where its ranking puts its first key image within kNear of it: a key image
  // that verifies everywhere does not rank first where the robot is not.
  void DoubtStalledTracker(LocalizationResult& result) const;
  // When the belief doubts the frame's position: compares around the belief's peak (over the whole route when
  // it is flat) and moves the estimate to the peak when the belief singles it out.
  void Question(LocalizationResult& result, const Frame& frame, const ImageFeatures& features);
  // A frame placed more than kNear route positions behind where the tracker was (and behind the place last steered
  // by), where an accepted key image within kNear of that estimate, beyond a little chance, verified nearly as many
  // matches as the place: the frame is `uncertain` and the tracker stays (LocalizerOptions::doubt_jump_back,
  // judge_jump_back_from_steered_place; localizer_jump_back.cc).
  void DoubtJumpBack(LocalizationResult& result);
  // The tracker at the key image before the route's last, `tracked` its comparison: whether it steps on to the last
  // one, `ahead` (LocalizerOptions::step_on_to_last_by_chance); nullopt where the rule does not decide.
  std::optional<bool> StepsOnToLastKeyImage(const KeyComparison& ahead, const KeyComparison& tracked,
                                            int ahead_position) const;
  // Track's lookahead stopped at the key image after `best_position`: where `best` and that key image both verify by
  // little beyond chance, the key image past it is compared, and becomes `best` where it verifies more, clearly beyond
  // chance (LocalizerOptions::look_past_weak_next, look_past_max_log10_nfa; localizer_look_past.cc).
  void LookPastWeakNext(const Frame& frame, const ImageFeatures& features, int position, KeyComparison& best,
                        int& best_position);
  // A key image further on than the tracker's next that verifies the frame more than the tracked one does, clearly
  // (log10 NFA at most LocalizerOptions::look_past_max_log10_nfa): the step LookPastWeakNext and LookFurtherWhenLagging
  // take.
  bool ClearlyBeats(const KeyComparison& further, const KeyComparison& tracked) const;
  // Compares route positions `first` to `last` (those on the route) and steps on to the one that ClearlyBeats `best`
  // and fits best, weighing the belief there ten to one where `weigh_belief`; false where none does.
  bool StepOnWhereClearlyBetter(const Frame& frame, const ImageFeatures& features, int first, int last,
                                bool weigh_belief, KeyComparison& best, int& best_position);
  // Up to lagging_start_frames frames after the run's first, a tracker at `best_position` that lags (lagging_start_)
  // and holds the frame by less than clearly compares the two key images after the next one, and the better becomes
  // `best` where it verifies more, clearly (LocalizerOptions::lagging_tracker_frames; localizer_lagging_tracker.cc).
  void LookFurtherWhenLagging(const Frame& frame, const ImageFeatures& features, KeyComparison& best,
                              int& best_position);
  // Where the distance driven puts the robot is driven_past_positions or more route positions past `best_position`:
  // the key images there are compared, and the better becomes `best` where it verifies more, clearly
  // (localizer_driven_ahead.cc).
  void LookWhereDriven(const Frame& frame, const ImageFeatures& features, KeyComparison& best, int& best_position);
  // Where the distance driven puts the robot within a route position of `tracked` and further from `elsewhere`: the
  // odometry vouches for the tracked key image, and a relocalization to `elsewhere` is not taken on one frame.
  bool DrivenVouchesFor(int tracked, int elsewhere) const;
  // After the frame's result is final: where the distance driven is counted from (pace_.CountDrivenFrom; the tracker
  // was at `position_before` when the frame began).
  void RememberWhereDriven(int position_before);
  // Compares the frame with the best-ranked key images of the route (relocalization_candidates of them), in
  // rank order; returns the ranking's route positions compared.
  std::vector<int> CompareBestRanked(const Frame& frame, const ImageFeatures& features);

  // The route's key images ranked for the frame (KeyImageRanking), best first; ranked once per frame.
  const std::vector<RankedKey>& RankRoute(const Frame& frame, const ImageFeatures& features);
  // The same ranking computed without keeping it: whether the frame was ranked is part of what the belief weighs.
  std::vector<RankedKey> RouteRanking(const Frame& frame, const ImageFeatures& features) const;
  // When no comparison of the frame is accepted: accepts the one with the most verified matches if it stands out
  // against its rivals, those compared more than kNear route positions away, the best-ranked of them always among
  // them (LocalizerOptions::min_rival_ratio; compared now when it was not). Returns its route position, -1 when none
  // is accepted.
  int AcceptAgainstRivals(const Frame& frame, const ImageFeatures& features);

  // A tracked comparison: comparisons_.Once, and when only the link share refuses it, judged against the frame's rivals
  // as a relocalized one is (AcceptAgainstRivals), on its own: at least min_rival_ratio times the verified matches of
  // every key image compared more than kNear route positions from it, the best-ranked such one among them (compared
  // now when it was not). Accepted so, it stays accepted for the rest of the frame.
  KeyComparison CompareTracked(const Frame& frame, const ImageFeatures& features, int position);
  // Accepted against the frame's rivals: accepted, though with fewer verified matches than the link share asks.
  bool AcceptedAgainstRivals(const KeyComparison& comparison) const;

  // The most verified matches of the frame's (accepted, where `accepted_only`) comparisons more than kNear route
  // positions from `position`, -1: none; RivalVerified's of all, the best-ranked such key image compared first.
  int MostVerifiedAway(int position, bool accepted_only) const;
  int RivalVerified(const Frame& frame, const ImageFeatures& features, int position);
  // The comparison may be accepted against the frame's rivals (kChance, min_rival_ratio > 0, matched and its log10
  // NFA at most rival_max_log10_nfa), and does stand out when it verifies min_rival_ratio times its rivals' best.
  bool MayStandOut(const KeyComparison& comparison) const;
  bool StandsOut(int verified, int rival_verified) const;
  // Across seasons with binary descriptors (min_heading_rival_ratio): the comparison at route `position` is accepted
  // where chance refused it when its heading mode holds at least min_heading_votes matches and min_heading_rival_ratio
  // times the heading votes of every heading rival compared (IsHeadingRival), the best-ranked one compared first when
  // it was not. Without a rival (a route too short) it is not: the frame cannot tell.
  bool HeadingStandsOut(const Frame& frame, const ImageFeatures& features, const KeyComparison& comparison,
                        int position);
  // Route position `q` is a heading rival of `position`: more than kNear away, or nearer but not joined to it by links
  // of one scene (scene_link_after_): another place, whose matches agree with the frame's only by chance.
  bool IsHeadingRival(int position, int q) const;
  // What both heading rules (HeadingStandsOut, AcceptLostFrameByHeading) ask of the comparison itself: matched, at
  // least min_heading_votes heading votes, and the link share's verified matches.
  bool HeadingMayStandOut(const KeyComparison& comparison) const;
  // And of its rivals: the most heading votes of a heading rival of route `position` among `compared` (the frame's
  // memos, or its comparisons with more features), which each rule's ratio of the comparison's votes must reach; -1
  // without a rival (a route too short): the frame cannot tell, and no heading stands out. Defined for both in
  // localizer_rivals.cc.
  template <typename Compared>
  int MostHeadingRivalVotes(int position, const Compared& compared) const;
  // When nothing else is accepted: the comparison whose heading mode holds the most votes, if HeadingStandsOut.
  // Returns its route position, -1 when none.
  int AcceptByHeading(const Frame& frame, const ImageFeatures& features);

  // A relocalization far from the tracked estimate (more than kNear route positions, plus `lookahead` for each of
  // the `lost_frames` frames lost since it was tracked): one frame's evidence (across lighting a chance match looks
  // alike) does not move the tracker; two frames in a row pointing there do, when the belief, weighed by both, holds
  // at least as much per position near it as near the tracked estimate. Returns whether the tracker moves from route
  // position `from` to `to`; when not, remembers `to` for the next frame. Only with the belief on (belief.window and
  // min_confidence above 0; localizer_takes_jump.cc).
  bool TakesJump(int from, int to, int lost_frames);
  // How far from the tracked estimate a place is near enough to need no second frame: kNear, plus `lookahead` for each
  // of the `lost_frames` frames lost since (the robot moved on unseen, as the tracker would have followed).
  int JumpReach(int lost_frames) const { return kNear + options_.lookahead * lost_frames; }
  // Remembers the far place the frame's comparisons verified more at than the key images it is steered by (or, for a
  // frame not steered by, than its key images: rival_place_when_not_steered) as rival_place_, or counts down the one
  // remembered.
  void RememberRivalPlace(const LocalizationResult& result);
  // Remembers the key image a frame placed behind the last frame placed moved the run back to as moved_back_to_, while
  // the frames after it are placed there (ask_where_moved_back).
  void RememberMoveBack(const LocalizationResult& result);
  // The tracker starts the frame at route `position`, more than kNear behind the place the last frame steered by was
  // at: uncertain frames moved it there (ask_where_guessed_back; localizer_guessed_back.cc).
  bool TrackedFromAGuessBehind(int position) const;
  // A frame not steered by compares the rival place (it and the key image after it), whose evidence then weighs the
  // belief; Track compares it for the frames it tracks (rival_place_when_not_steered).
  void CompareRivalPlace(const LocalizationResult& result, const ImageFeatures& features);
  // The route position, more than kNear from the result's, of the frame's accepted comparison that verified the most
  // matches, more than the result's key images; -1: none.
  int OutVerifiedFrom(const LocalizationResult& result) const;
  // The belief's mass per route position within kNear of `position` (fewer positions at the route's ends).
  double NearDensity(int position) const;
  // The route positions within kNear of `position` (fewer at the route's ends).
  int NearWidth(int position) const;
  // Whether a place can be singled out at route `position`: it and the two key images either side hold at most half
  // the route (not on michigan_seasons' routes of 5 places).
  bool TellsNearFromFar(int position) const;

  // The frame's verified matches with key_a over those of the map's link between key_a and key_b (0 when
  // they have no link).
  double SharedWithLink(const KeyComparison& comparison, int key_a, int key_b) const;
  // A move of the tracker from comparison `from` to comparison `to` is not one chance explains better: `to`'s log10
  // NFA is at most `from`'s, both clamped at the evidence's bound (-max_significance), beyond which both are the same
  // scene beyond doubt (LocalizerOptions::step_back_needs_lower_nfa, step_on_needs_lower_nfa).
  bool NoLikelierChance(const KeyComparison& to, const KeyComparison& from) const;
  // A tracked comparison shares less with its key image than the map's links do (recheck_link_share).
  bool SharesLittle(const KeyComparison& comparison) const;

  // "Near" a route position: within two (key images two apart often both see the frame); the tolerance of the
  // goal "no frame confidently at a key image more than 2 places away".
  static constexpr int kNear = 2;
  // The furthest a key image is compared along the route for the link share's reference (link_share_tau): at most
  // this many comparisons a key image when the localizer starts.
  static constexpr int kLinkShareReach = 10;
  // A comparison verifies beyond a little chance at a log10 NFA of at most this (the bar of
  // LocalizerOptions::scene_change_tracked_log10_nfa), read by the doubted jump back and the look past a weak next key
  // image: across lighting a place the robot left still accepts a few chance matches at -6 or so.
  static constexpr double kBeyondLittleChance = -10.0;
  // A next key image whose comparison is above this log10 NFA (or unmatched) sees nothing of the frame beyond what
  // chance gives a place the robot left (stalled_tracker_frames).
  static constexpr double kWithinLittleChance = -6.0;

  const VisualMap& map_;
  const KeyImageStore& keys_;
  const Matcher& matcher_;
  std::unique_ptr<Matcher> guided_matcher_;  // ORB without the cross check; null: no guided matching
  std::unique_ptr<Matcher> window_matcher_;  // the window matching's features (window_features); null: the map's
  // A lost frame's second look (LocalizerOptions::lost_frame_features); null: not asked, not ORB, or the key images'
  // directory unknown or unreadable.
  std::unique_ptr<LostFrameMatcher> lost_frame_matcher_;
  LocalizerOptions options_;
  KeyImageComparer comparer_;     // its link share's reference: link_verified_, or at link_share_tau's spacing
  HeadingContinuity continuity_;  // the previous frame's headings, which guided matching predicts the frame's by
  std::vector<int> route_;
  std::vector<int> route_position_of_key_;  // -1 for key images off the route
  // Per key image: the verified matches of its link with a route neighbour, the smaller of the two; 0 when it
  // has no verified link on the route (the comparisons against the map's links are then skipped). The recheck and the
  // evidence read these even where the comparer's reference is at link_share_tau's spacing: on a map of every frame a
  // frame tracked with less than its near-duplicate links share is still asked whether a key image on verifies more.
  std::vector<int> link_verified_;
  // Per route position p: the map's link between p and p + 1 is of one scene (its verified matches pass chance, as a
  // comparison's must). A --tau 1 map of unrelated places has links chance refuses; a teach run's are of one scene.
  std::vector<bool> scene_link_after_;
  // Binary descriptors (ORB): a heading mode that stands out against the frame's rivals accepts a comparison
  // (min_heading_rival_ratio; measured on ORB only).
  bool heading_accepts_ = false;
  bool warned_stretched_ = false;  // a frame of another shape than the map's was said
  // ORB: the comparisons away from the tracker are verified with fewer iterations (far_comparison_iterations; XFeat's
  // scored matches are verified on their best, MapVerifierOptions' loop_points, and were not measured so).
  bool binary_descriptors_ = false;
  std::unique_ptr<KeyImageRanking> ranking_;
  int position_ = -1;  // route position of `key`; -1: no estimate
  // position_ and the lookahead (MotionPace::Lookahead) when the frame being localized started: fixed for the frame, so
  // that a comparison's result (FarComparisonIterations) does not depend on when or on which thread it is made.
  int frame_start_position_ = -1, lookahead_ = 2;
  int start_position_ = -1;  // route position of LocalizerOptions::start_key; -1: none
  int lost_in_a_row_ = 0;
  // The route position the frame before this one was placed at (tracking or relocalized); -1: it was not.
  int placed_before_ = -1;
  // The route position of the last frame placed, whatever the frames after it (-1: none since the start or a reset),
  // and the route position a placed frame moved back to behind it, while the frames after it are placed there (-1:
  // none; LocalizerOptions::ask_where_moved_back).
  int steered_before_ = -1;
  int moved_back_to_ = -1;
  // The frame before's features as the matcher serializes them, kept where a rule that steps a frame on may ask
  // whether it stands still (StillSinceFrameBefore); empty: not kept, or the run had no estimate after that frame.
  std::string features_before_;
  bool keeps_features_before_ = false;
  // What the frame before this one named by its own evidence: its RankingFirst() and its HeadingMode() (-1: none).
  int ranking_first_before_ = -1;
  int heading_mode_before_ = -1;
  // Where the estimate was last dropped (route position; -1: none) and the frames since, while guided_while_lost
  // still asks there.
  int dropped_position_ = -1;
  int frames_since_drop_ = 0;
  // The step back last ruled out (Track): at route position `position`, on the frame before this one, with the
  // frame's verified matches with the next key image at that last check. position -1: none.
  struct StepBackRuledOut {
    int position = -1, next_verified = 0;
  } step_back_ruled_out_;
  RouteBelief belief_;
  MotionPace pace_;  // the motion model's steps a frame, and where the distance driven puts the robot
  // The belief the frames' evidence alone would hold: the same motion and comparisons as belief_, from a flat start
  // (without the start key image's prior). Kept only while the start is unconfirmed, the only time it is read.
  RouteBelief evidence_belief_;
  // The start key image is a hint the frames have not yet confirmed (start_is_hint): until a frame is steered by near
  // the evidence belief's peak, the evidence belief may make a frame uncertain, and with binary descriptors every frame
  // is also compared with the best-ranked key images of the whole route.
  bool start_unconfirmed_ = false;
  // ORB: a wrong key image's comparison weighs against it, so comparing the whole route checks the start (XFeat's
  // chance matches at most wrong key images pulled the evidence belief to chance places: docs/localize.md).
  bool start_checked_over_route_ = false;
  // ORB: the log10 NFA ranks the key images near the frame as the verified count does (its verified sets at wrong key
  // images almost never pass chance; XFeat's do, and a step on needing a lower NFA held its frames a key image back).
  bool nfa_ranks_key_images_ = false;
  // After the frame's motion step, before its evidence: the belief held at least min_confidence near its peak
  // (the frames before this one singled out a place). A flat belief does not move the estimate.
  bool belief_confident_ = false;
  LaggingStart lagging_start_;  // where the tracker was after the run's last few first frames
  StalledTracker stall_;        // the frames in a row the tracker was held where the next key image sees nothing
  int placed_in_a_row_ = 0;     // frames placed (tracking or relocalized) in a row before this one
  // A far route position that verified more than the place the last frames were steered by (rival_place_frames);
  // -1: none. Compared again for rival_frames_left_ more frames.
  int rival_place_ = -1;
  int rival_frames_left_ = 0;
  // The comparison StartPlaceTiesFar made for its question alone this frame, until WeighStartQuestion weighs it.
  std::optional<KeyComparison> start_question_;
  int pointed_ = -1;         // the far route position this frame's relocalization pointed at; -1: none
  int pointed_before_ = -1;  // the previous frame's
  int steps_on_ = 0;         // how many key images Track moved the estimate on this frame (LocalizerOptions::lookahead)
  // The route position a step back of this frame left (Track's step back, or the recheck's relocalization behind the
  // tracked estimate); -1: none.
  int stepped_back_from_ = -1;
  bool blind_ = false;      // the frame has fewer features than a comparison needs: its evidence weighs nothing
  EvidenceModel evidence_;  // by the kind of the matcher's descriptors
  using Memo = FrameComparisons::Memo;
  std::vector<RankedKey> ranked_;  // the route ranked for the frame being localized (RankRoute); empty: not yet
  // The frame's ranking weighs the belief (WeighRanking): each route position's bucket in it (RankingBuckets); empty:
  // not yet.
  std::vector<int> bucket_of_position_;
  // The belief's peak after the motion step, before the frame's evidence, when it singled out a place (-1: it did
  // not), on this frame and the one before (RouteBeliefOptions::move_needs_two_frames).
  int confident_peak_ = -1;
  int confident_peak_before_ = -1;
  // The frame's comparisons, each made once (made meanwhile on comparison_threads - 1 helper threads). Last: its
  // helpers are stopped before the members their comparisons read are destroyed.
  FrameComparisons comparisons_;
};

}  // namespace vmap
