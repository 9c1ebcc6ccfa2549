#pragma once
// What the Localizer says of one frame (LocalizationResult), and what a controller may steer by.

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "vmap/core/enum_names.h"
#include "vmap/localization/key_comparison.h"

namespace vmap {

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

// The rule that made a frame uncertain (LocalizationResult::withheld_by): what an audit of a run needs to tell a
// doubt of the belief from one of the tracker. docs/localize.md describes each rule.
enum class Withholding {
  kNone,                  // not uncertain
  kBelief,                // the belief holds too little near the place, or the frames' evidence points away
  kStartUnconfirmed,      // the run's start place ties a far one, or lies where the belief has not followed
  kLittleChance,          // placed away from the belief by comparisons little beyond chance
  kFarPlaceOnOneFrame,    // a far place verified on this frame alone: a jump needs the next frame too
  kFarPlaceVerifiesMore,  // tracked, while a far place verified more on this frame
  kJumpBack,              // a jump back that the key images near the estimate verify against
  kStalledTracker,        // held at a key image while the ranking puts the frame elsewhere
  kBeliefMoved,           // the belief moved the estimate off the tracker's place, and no key image verifies there
};
inline constexpr EnumName<Withholding> kWithholdingNames[] = {
    {Withholding::kNone, ""},
    {Withholding::kBelief, "belief"},
    {Withholding::kStartUnconfirmed, "start unconfirmed"},
    {Withholding::kLittleChance, "little chance"},
    {Withholding::kFarPlaceOnOneFrame, "far place on one frame"},
    {Withholding::kFarPlaceVerifiesMore, "far place verifies more"},
    {Withholding::kJumpBack, "jump back"},
    {Withholding::kStalledTracker, "stalled tracker"},
    {Withholding::kBeliefMoved, "belief moved"}};
std::string WithholdingName(Withholding rule);
// Placed: verified at a key image of the route and not doubted, the only frames a robot may steer by (with a
// heading: MaySteerBy) and the only ones that move the estimate's own key image.
constexpr bool IsPlaced(LocalizationStatus status) {
  return status == LocalizationStatus::kTracking || status == LocalizationStatus::kRelocalized;
}

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
  Withholding withheld_by = Withholding::kNone;  // why the frame is uncertain; kNone for any other status
  int key = -1;                                  // the key image the frame is at (the last reached), -1 when unknown
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
  // The times the belief's motion model moved it before this frame's evidence (MotionPace: the route positions the
  // run passed since the frame before, three steps a position). 0 when unknown.
  int motion_steps = 0;
  // The belief over the route after this frame: (key image, mass) for each route position holding at least 1 % of
  // it (position p at its key image, the start of segment p), in route order; empty when not computed. The
  // report's plot of the belief over time (report/belief_plot.h) draws it; the JSON lists it, the CSV does not.
  std::vector<std::pair<int, double>> belief;
};

// What a controller may use of a result: "heading and translation", "heading only: translation unknown"
// (a pose whose translation direction is not to be trusted), "heading only: no pose" (no camera, or no pose
// to the target), or nothing to steer by: "none: lost" (kLost), "none: position uncertain (RULE)" (kUncertain: the
// key images are a guess; RULE names withheld_by, and is left out where none is set), "none" (no heading). Every value
// that starts with "none" means: do not steer by this frame.
std::string LocalizationGuidance(const LocalizationResult& result);
// Whether a controller may steer by the result: tracking or relocalized, with a heading to the target
// (LocalizationGuidance does not start with "none").
bool MaySteerBy(const LocalizationResult& result);

}  // namespace vmap
