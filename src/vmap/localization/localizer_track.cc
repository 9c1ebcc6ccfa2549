// The tracker along the route (Localizer::Track): the frame compared with the tracked key image and those ahead and
// behind, stepped on or back, and, where nothing there verifies, relocalized, placed by agreement or held.
#include <algorithm>
#include <cstdlib>
#include <optional>
#include <utility>

#include "vmap/localization/localizer.h"

namespace vmap {

namespace {

// A previous key image with fewer verified matches than this share of the key image's is clearly the worse
// match: the step back is not checked again until the frame moves back (Localizer::Track). Chosen on lab_floor
// (docs/measurements/code-choices.md, "Ruling out a step back").
constexpr double kClearlyWorse = 0.7;

}  // namespace

LocalizationResult Localizer::Track(const Frame& frame, const ImageFeatures& features) {
  LocalizationResult result;
  const int last = static_cast<int>(route_.size()) - 1;
  // Across seasons the link share refuses the tracked key images too: each is judged against the frame's own rivals
  // then (a rival or two compared, where a relocalization would compare the ranking's five and their neighbours).
  auto compare_at = [&](int position) { return CompareTracked(frame, features, position); };
  const int position = position_;
  const int lost_before = lost_in_a_row_;  // frames lost since `position` was tracked
  const KeyComparison at_key = compare_at(position);
  KeyComparison best = at_key;
  int best_position = position;
  // Move on while the key image ahead is the better match, at most `lookahead` key images (more where they crowd).
  for (int step = 1; step <= lookahead_ && position + step <= last; ++step) {
    const KeyComparison ahead = compare_at(position + step);
    // A tie is no step on: the frame is as near the one as the other, on the segment it is on. With ORB, neither is a
    // step on that chance explains better than the key image left behind (a frame a teach frame short of it).
    const bool beats_best =
        !best.accepted ||
        ((!options_.step_on_needs_more || ahead.num_verified > best.num_verified) &&
         (!nfa_ranks_key_images_ || !options_.step_on_needs_lower_nfa || NoLikelierChance(ahead, best)));
    const std::optional<bool> to_last = StepsOnToLastKeyImage(ahead, best, position + step);
    if (to_last ? !*to_last : (!IsBetterMatch(ahead, best) || !beats_best)) {
      // A frame that verifies against nothing so far may still have passed the next key image quickly. With ORB, one
      // that verifies exactly as much with the key image ahead as with the best may have passed both: where key
      // images crowd (rccar_room's fast turn, a key image every frame or two), each sees the frame's scene alike,
      // and only the one after them tells. Not with XFeat, whose key images near a frame tie often across lighting
      // (corridor_conditions: one right frame fewer with it, docs/localize.md).
      const bool tie =
          binary_descriptors_ && best.accepted && ahead.accepted && ahead.num_verified == best.num_verified;
      // Where the run passed the whole lookahead since the frame before (key images crowd within the frames it passed:
      // MotionPace::PassedLookahead), each of them sees the frame's scene alike, and one that verifies a little less by
      // chance says nothing of those after it: all are compared.
      const bool passed_all = options_.lookahead_by_pace && pace_.PassedLookahead(position, options_.lookahead);
      if ((best.accepted || step > 1) && !tie && !passed_all) break;
      continue;
    }
    best = ahead;
    best_position = position + step;
  }
  LookPastWeakNext(frame, features, position, best, best_position);
  LookFurtherWhenLagging(frame, features, best, best_position);
  LookWhereDriven(frame, features, best, best_position);
  // Not moved on, and nearer `key` than `next_key`: the frame may be behind `key` (a robot that reversed, a
  // hand-held camera swinging back, a relocalization one key image too far). Move back when the previous key
  // image is the better match. Checked only near `key`, where it can be true, to spare a comparison.
  // Checked again on the frames that follow a check that found the previous key image clearly worse only once
  // the frame shares fewer verified matches with the next key image than it did then: until then it has not
  // moved back, and one comparison in 2.4 is spared on most frames near a key image (docs/localize.md).
  const StepBackRuledOut ruled_out = std::exchange(step_back_ruled_out_, {});
  // Stepped back with nothing at or ahead of `key` accepted and `key` refused by chance itself, not only by the link
  // share: the key image the frames were at no longer sees the frame's scene.
  bool lone_step_back = false;
  if (options_.step_back && best_position == position && position > 0) {
    const KeyComparison next = position < last ? compare_at(position + 1) : KeyComparison();
    const int v_key = at_key.accepted ? at_key.num_verified : 0;
    const int v_next = next.accepted ? next.num_verified : 0;
    if (3 * v_next < v_key + v_next || v_key == 0) {
      if (v_key > 0 && ruled_out.position == position && v_next >= ruled_out.next_verified) {
        step_back_ruled_out_ = ruled_out;
      } else {
        const KeyComparison behind = compare_at(position - 1);
        // With nothing accepted at or ahead of `key`, the key image behind has nothing to beat but chance, and a step
        // back is the likelier chance on a route that goes forwards: it must beat chance by more.
        const bool beats_chance = best.accepted || behind.log10_nfa <= options_.step_back_max_log10_nfa;
        // A tie is no step back, nor a step back that chance explains better than the key image it would leave: the
        // route goes forwards.
        const bool beats_best =
            !best.accepted || ((!options_.step_back_needs_more || behind.num_verified > best.num_verified) &&
                               (!options_.step_back_needs_lower_nfa || NoLikelierChance(behind, best)));
        if (IsBetterMatch(behind, best) && beats_chance && beats_best) {
          lone_step_back = !best.accepted && !(at_key.matched && at_key.log10_nfa <= options_.max_log10_nfa);
          best = behind;
          best_position = position - 1;
        } else if (v_key > 0 && behind.num_verified < kClearlyWorse * v_key) {
          step_back_ruled_out_ = {position, v_next};
        }
      }
    }
  }
  if (!best.accepted) {
    // After a drop, until a frame is steered by again, asked whatever the belief (Reacquire).
    const int guided = TrackGuided(frame, features, position, /*whatever_the_belief=*/dropped_position_ >= 0);
    if (guided >= 0) return TrackedAt(std::move(result), position, guided, features);
  }
  if (!best.accepted) {
    // Lost against the estimate: the frame may be elsewhere on the route (the robot turned back, skipped
    // ahead, or the estimate was wrong). Look for it over the whole route at once; keep the estimate when
    // that fails too.
    LocalizationResult found = Relocalize(frame, features);
    // Nothing verified there either: the ranking's best asked again with the looser matching (a dark stretch of the
    // place the robot was carried to verifies only so).
    if (found.status != LocalizationStatus::kRelocalized && options_.guided_relocalization &&
        GuideRelocalization(frame, features)) {
      found = Relocalize(frame, features);
    }
    // Nothing verified with the map's features: the ranking's best compared again with more (across seasons too few of
    // 500 features match a right key image's for chance).
    const SecondLook look = found.status == LocalizationStatus::kRelocalized ? SecondLook::kNothing
                                                                             : CompareLostFrameAgain(frame, features);
    if (look != SecondLook::kNothing) {
      found = Relocalize(frame, features);
      // Placed by a heading that stands out less than the rule's ratio: placed, not steered by, as a frame placed by
      // agreement (michigan_seasons: 7 of the 17 frames placed so more than 35 px off the hand label).
      if (look == SecondLook::kPlacedOnly && found.status == LocalizationStatus::kRelocalized) {
        found = PlacedByAgreement(std::move(found));
      }
    }
    const bool relocalized = found.status == LocalizationStatus::kRelocalized;
    if (relocalized && TakesJump(position, found.route_position, lost_before)) return found;
    // Nothing verified anywhere: the frame's ranking and heading modes, each too weak for chance alone, step it on
    // where both name the key image after the one the frame before was placed at (the robot seen there, this frame
    // names where it goes next; a robot that stops shows the same place again, which names the same key image).
    const bool after_placed = placed_before_ == position && options_.step_on_where_evidence_agrees;
    // After lost frames, where the frame before, lost too, named that key image by neither measure: a robot that
    // stops shows the same place on every frame, which names the same key image.
    const bool after_lost = placed_before_ != position && lost_before > 0 && options_.step_on_after_lost_frames &&
                            ranking_first_before_ != position + 1 && heading_mode_before_ != position + 1;
    // A robot that stops shows the same place again, and a noisy copy of it can name the next key image as a lost
    // frame's weak evidence often does: a frame standing still is not stepped on.
    if (!relocalized && (after_placed || after_lost) && EvidenceAgreesOnNext(position) &&
        !StillSinceFrameBefore(features)) {
      // The lost frames before left the belief where chance put it: the agreement is weighed there first, by what it
      // tells a right key image from a wrong one on the lost frames of michigan_seasons (kAgreementLogRatio).
      if (after_lost) {
        WeighBeliefs(position + 1, kAgreementLogRatio);
        NormalizeBeliefs();
      }
      result.candidates = std::move(found.candidates);
      return PlacedByAgreement(TrackedAt(std::move(result), position, position + 1, features));
    }
    // Lost, or found far from where the frames were on this frame's evidence alone: the estimate stays (uncertain,
    // the best guess, until the next frame confirms the far place).
    result.status = relocalized ? LocalizationStatus::kUncertain : LocalizationStatus::kLost;
    if (relocalized) result.withheld_by = Withholding::kFarPlaceOnOneFrame;
    result.candidates = std::move(found.candidates);
    position_ = position;
    lost_in_a_row_ = lost_before + 1;
    if (lost_in_a_row_ <= options_.max_lost_frames) {
      Describe(result, position, features);
      return result;
    }
    // The estimate is dropped, from this frame on (as max_lost_frames says); the belief is kept (its evidence still
    // says where the frames were). A far place found on this frame's evidence alone is asked again by the next frame.
    result.status = LocalizationStatus::kLost;
    if (options_.guided_while_lost) dropped_position_ = position;
    frames_since_drop_ = 0;
    position_ = -1;
    lost_in_a_row_ = 0;
    step_back_ruled_out_ = {};
    return result;
  }
  // A rival place (rival_place_frames) asked again: where it verifies more than the tracked key image, the frame may be
  // there, and is relocalized as a frame that shares little with its key image is.
  bool rival_beats = false;
  if (rival_place_ >= 0 && std::abs(rival_place_ - best_position) > kNear) {
    for (int q = rival_place_; q <= std::min(last, rival_place_ + 1); ++q) {
      const KeyComparison c = comparisons_.Once(features, route_[q]);
      if (c.accepted && c.num_verified > best.num_verified) rival_beats = true;
    }
  }
  bool doubted = false;  // a lone step back, a changed scene or a move back, while a far relocalization verified more
  // Carried off since the frame before (scene_change_log10_nfa): the key image left may still accept a few chance
  // matches, which one frame steered by there would follow. Asked only where those are all the frame holds there
  // (scene_change_tracked_log10_nfa): a frame far beyond chance at its key image is there, whatever the frame before.
  const bool rivals_decided = AcceptedAgainstRivals(best);
  const bool scene_changed = !rivals_decided && best.log10_nfa > options_.scene_change_tracked_log10_nfa &&
                             SceneChangedSinceFrameBefore(features);
  // Where the run moved back (ask_where_moved_back), a look-alike key image behind holds the tracker.
  const bool moved_back =
      options_.ask_where_moved_back && !binary_descriptors_ && moved_back_to_ >= 0 && best_position == moved_back_to_;
  // Where uncertain frames moved the tracker far behind the place last steered by (ask_where_guessed_back), the same.
  const bool guessed_back = TrackedFromAGuessBehind(position);
  if (!rivals_decided &&
      (SharesLittle(best) || pointed_before_ >= 0 || rival_beats || scene_changed || moved_back || guessed_back)) {
    // Accepted, but with much less than neighbouring key images share: the frame may be elsewhere on the
    // route, in view of this key image's scene. Moved when a ranked key image verifies more matches (a
    // relocalization that is not taken leaves nothing behind: the tracked estimate is set below). Also asked when
    // the previous frame pointed far: a far place needs two frames (TakesJump), and the second may still keep half
    // its key image's link (redkitchen's hand-held camera held one key image 15 frames past blurred ones ahead).
    LocalizationResult found = Relocalize(frame, features);
    int found_verified = 0;
    for (const RelocalizationCandidate& c : found.candidates) {
      if (c.accepted) found_verified = std::max(found_verified, c.num_verified);
    }
    if (found.status == LocalizationStatus::kRelocalized && found_verified > best.num_verified &&
        !DrivenVouchesFor(best_position, found.route_position)) {
      if (TakesJump(position, found.route_position, lost_before)) {
        if (found.route_position < position) stepped_back_from_ = position;
        return found;
      }
      // A far place verifies more, on one frame: no jump yet. The key image behind, all that still verifies where the
      // frames were, holds the tracker as a lost frame's estimate is held: not steered by (the robot may have been
      // carried off; the next frame is asked again and decides).
      doubted = (lone_step_back && options_.doubt_lone_step_back) || scene_changed ||
                (moved_back && options_.doubt_where_moved_back);
    }
  }
  if (best_position < position) stepped_back_from_ = position;
  result = TrackedAt(std::move(result), position, best_position, features);
  if (doubted) {
    result.status = LocalizationStatus::kUncertain;
    result.withheld_by = Withholding::kFarPlaceVerifiesMore;
  }
  return result;
}

LocalizationResult Localizer::TrackedAt(LocalizationResult result, int from, int position,
                                        const ImageFeatures& features) {
  lost_in_a_row_ = 0;
  position_ = position;
  steps_on_ = std::max(0, position - from);
  result.status = LocalizationStatus::kTracking;
  Describe(result, position_, features);
  return result;
}

}  // namespace vmap
