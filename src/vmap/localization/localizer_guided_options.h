#pragma once
// The Localizer's guided matching (ORB maps): how a frame that verifies weakly at the key images the belief singles
// out is matched with them again (LocalizerOptions derives from it; localizer_options.cc gives the fields' flags).

namespace vmap {

struct GuidedMatchingOptions {
  // Guided matching (ORB maps): a frame that verifies nothing at the tracked key images while the belief singles
  // out that place is matched with them again, and only with them, keeping one-way best matches too (no cross
  // check); the a-contrario test, which counts every tentative match, decides as before (docs/localize.md,
  // "Guided matching by the belief"). Off: never.
  bool guided_matching = true;
  // Guided matching after the estimate was dropped (`max_lost_frames`): for as many frames again, until a frame is
  // steered by, a frame that verifies nothing is still matched guided at the key image the tracker last held (or holds
  // again) and the one after it, whatever the belief (flat by then: nothing verified for frames), and tracked there
  // when its own guided comparison is accepted; a frame that a ranked key image verifies is relocalized first
  // (docs/localize.md). Off: a dropped estimate is only relocalized.
  bool guided_while_lost = true;
  // Guided relocalization: a tracked frame that verifies nothing at the tracked key images, guided there too, and whose
  // relocalization verifies nothing either, is matched guided with the ranking's best key images
  // (relocalization_candidates of them) whose first comparison verified the link share, and relocalized again on what
  // chance accepts of them. The a-contrario test decides as for every guided comparison, and a place far from the
  // tracked estimate still needs two frames (TakesJump). A robot carried back (corridor_conditions' kidnapped run,
  // repeat frames 22-24) is relocalized frames sooner (docs/measurements/localization-conditions.md, "A lost frame's
  // relocalization is matched guided"). Off: a lost frame's relocalization compares the cross-checked matches only.
  bool guided_relocalization = true;
  // Guided matching over the lookahead: it asks the tracked key image and the `lookahead` key images after it (the
  // tracker's own reach), and ranks what it accepts by a measure common to the key images asked: those chance accepts
  // by their verified matches (as the tracker ranks), and when chance accepts none, those the continuity of the heading
  // or the window accepted by the log10 NFA of their one-way guided matches, the one test made the same way at each
  // key image (the verified counts of those two tests are not comparable with each other: the window's come from
  // features extracted again). A robot that passes a key image a frame (corridor_conditions frames 97-99) is otherwise
  // held one key image behind by a comparison the continuity accepts. Off: the key image and the next one only,
  // ranked by verified matches.
  bool guided_lookahead = true;
  // The continuity of the heading (guided matching only): a guided comparison chance refuses is accepted when the
  // frame moves as the previous frame did against the same key image. At least `continuity_share` of its tentative
  // matches move by the previous frame's heading against that key image (within 1/40 of the image's width across,
  // 1/20 of its height up or down: a robot turns slowly, chance matches have no reason to), its first comparison's
  // heading mode holds at least `continuity_heading_confidence` of its matches and that comparison's log10 NFA is at
  // most `continuity_max_log10_nfa`. Measured against wrong key images with the prediction a run would have there
  // (docs/localize.md, "Continuity of the heading"). 0 share: never.
  double continuity_share = 0.18;
  double continuity_heading_confidence = 0.43;
  double continuity_max_log10_nfa = 7.5;
  // Matching guided by the prediction (guided matching only, where the continuity rule did not accept): the frame's
  // features extracted again (FAST threshold `window_fast_threshold`, `window_features` of them; 0: the map's) and
  // matched with the key image only within a window around the previous frame's heading against it
  // (features/orb_matcher.h, MatchOrbInWindow: `window_width` of the image's width across and 1/20 of its height up
  // or down, both widened by `window_zoom` times the feature's distance from the image's centre; pyramid levels at
  // most 1 apart, Hamming distance at most 64, ratio 0.9 among the window's candidates). Accepted when the a-contrario
  // count of those matches is at most `window_max_log10_nfa` and the first comparison passes the continuity rule's
  // guards (continuity_heading_confidence, continuity_max_log10_nfa). Such matches agree with the prediction by
  // construction, so that count is no chance: the threshold was measured against wrong key images with the prediction
  // a run would have there (docs/localize.md, "Matching guided by the prediction"). Off: never.
  bool window_matching = true;
  double window_width = 0.1;
  double window_zoom = 0.15;
  int window_fast_threshold = 7;
  int window_features = 1000;
  double window_max_log10_nfa = -1.5;
};

}  // namespace vmap
