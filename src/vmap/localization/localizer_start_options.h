#pragma once
// Where a Localizer's run starts and how its start is confirmed (LocalizerOptions derives from it;
// localizer_options.cc gives the fields' flags).

namespace vmap {

struct StartOptions {
  // The key image the run starts at (a teach-and-repeat robot starts where the teach run started: the route's
  // first key image), or -1: anywhere (the first frame is relocalized over the whole route). The tracker starts
  // there and the belief holds `start_mass` there (the rest spread over the route as a flat belief): a soft prior,
  // which the frames' evidence overrides when the run starts elsewhere (docs/localize.md, "The start"). 0.8 rather
  // than 0.5: XFeat's first frames across lighting weigh far key images too, and half the belief did not keep them
  // near the start (corridor_conditions frames 5-6; a run started elsewhere pays a frame or two more of doubt).
  int start_key = -1;
  double start_mass = 0.8;
  // The start key image is a hint, not evidence: a frame is `uncertain`, not steered by, where the belief the frames'
  // evidence alone would hold (the same comparisons, weighed from a flat start) singles out a place more than two key
  // images from it and holds less than min_confidence near it. The start's prior lends confidence where the frames do
  // not tell, never against what they tell: a robot started elsewhere than `start_key` says is not steered by the
  // start key image's neighbours while its frames point elsewhere (docs/localize.md, "The start is a hint"). Without
  // `start_key` both beliefs are one. Off: the start's prior alone decides.
  bool start_is_hint = true;
  // With start_is_hint, a frame is also `uncertain` while the start is unconfirmed where the frames' evidence alone
  // holds less near its key image than a flat belief would: the frames weigh against the place, and only the start's
  // prior holds it there. Across lighting a chance match near the start key image is accepted now and then, and the
  // prior made it confident (corridor_conditions from repeat frame 20 with ORB: frame 23 steered by key image 1, teach
  // frame 4; docs/localize.md, "The start needs the frames' evidence"). Only on routes where a key image and the two
  // either side hold at most half the key images (as a place can be singled out there). Off: only a place the
  // evidence singles out elsewhere makes the frame uncertain.
  bool start_needs_evidence = true;
  // With start_is_hint and float descriptors (XFeat), while the start is unconfirmed a frame placed (tracking or
  // relocalized) is also `uncertain`, and does not confirm the start, where a key image more than two route positions
  // from its place verified at least as many matches as its own accepted key images, or weighs at least as much by the
  // evidence model: one the frame compared, or else the best-ranked key image that far, compared for this question
  // alone (not weighed: the belief and the tracker are as without the rule). Across lighting XFeat verifies as much at
  // corridor_conditions' look-alike stretches as at the right key images, and a run started elsewhere has no run of
  // frames behind it to tell them apart: over the verifier's seeds 0-11 the runs started elsewhere had 16 frames
  // steered by more than 2 key images off, 9 with the rule (7 of them placed so before the start was confirmed; none
  // new), at the price of 23 right frames uncertain in 48 runs (docs/measurements/localization-conditions.md, "A run
  // started elsewhere confirms a place that stands out"). Only on routes where a key image and the two either side
  // hold at most half the route (as start_needs_evidence). Off: a frame confirms the start by the beliefs alone.
  bool start_place_stands_out = true;
  // With start_place_stands_out, the far key image compared for its question alone is evidence like any comparison: it
  // weighs both beliefs once the frame is decided (the frame's own status and key images as without it), so the
  // frames after it carry what it verified. Left unweighed, a run started elsewhere whose tracker reached a look-alike
  // had the right place weighed mostly where the tracker compared it: the kidnapped run from its frame 51 (repeat frame
  // 80, started at key image 0) at the verifier's seeds 75, 216, 227 and 228 was steered by at key images 11-13
  // (right: 23-31) on 20 frames; weighed, none, and the belief finds the right place on the run's first frames. It is
  // weighed whichever way it points: where the tracker is right, a look-alike's comparison pulls the belief too, and a
  // few first frames of a run are uncertain rather than steered by (docs/measurements/localization-conditions.md, "The
  // start's question weighs the belief"). Off: the question's comparison is not weighed.
  bool start_question_weighs = true;
  // With start_is_hint and float descriptors (XFeat), while the start is unconfirmed a frame placed without being
  // ranked (the tracker's) weighs the frames' evidence alone (not the belief: the tracker is as without it) by its
  // ranking, as a ranked frame weighs both: that evidence otherwise holds a tracked frame's comparisons only where the
  // tracker compared them, and a tracker moved to a look-alike by a guess pulls it there. The corridor from repeat
  // frame 90 at the verifier's seed 12: frame 92 tracked at key image 13 (right: 28-30) swung it from 28 to 12 and
  // confirmed the start 15 key images off, frames 92-94 steered by there; with it they are uncertain. Over the
  // verifier's seeds 0-15 on the runs started elsewhere, frames steered by more than 2 key images off 10 -> 7, none
  // new, 63 of 64 CSVs the same (docs/measurements/localization-conditions.md, "A start confirmed at a look-alike is
  // asked by the frame's ranking"). Only on routes where a key image and the two either side hold at most half the
  // route (as start_needs_evidence). Off: the frames' evidence weighs a tracked frame by its comparisons alone.
  bool start_evidence_ranks_frame = true;
  // With start_is_hint and float descriptors (XFeat), while the start is unconfirmed a frame placed more than two route
  // positions from the start key image is also `uncertain`, and does not confirm the start, where the belief holds less
  // than this near it: a place away from where the user said the run starts must win the belief, not half of it. Two
  // dark frames confirmed corridor_conditions' corridor from repeat frame 50 at key image 29 (right: 13-15) with
  // 0.61-0.73 (the verifier's seeds 22 and 35); right starts away held 0.70-1.0, 4 of 118 below 0.9 (seeds 0-39;
  // docs/measurements/localization-conditions.md, "A start away from the start key image needs the belief"). Only where
  // a key image and the two either side hold at most half the route (as start_needs_evidence). 0: off.
  double start_away_min_confidence = 0.9;
};

}  // namespace vmap
