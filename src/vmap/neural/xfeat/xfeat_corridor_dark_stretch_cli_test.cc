// `vmap localize` with XFeat on corridor_conditions' dark stretch (repeat frames 50-55, dark in the repeat run): frames
// that verify little where they are and, through the fisheye's rim matching itself, a little beyond chance at the
// route's end (key images 29-31). Each test a slice of the runs bench/route_conditions.py measures, where a rule of the
// localizer keeps such a frame from being steered by far from where it is (docs/localize.md); the fixture:
// xfeat_corridor_run.h.

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/neural/xfeat/xfeat_corridor_run.h"

namespace vmap::neural {
namespace {

// A jump back is judged from where the run was steered (docs/localize.md): repeat frames 0-62 started at key image 0
// (bench/route_conditions.py's corridor run), at the verifier's seed 106. After the dark stretch an unconfirmed
// relocalization left the tracker at key image 30 (the route's end) while the run was last steered by at key image 14
// (frame 49); frames 56-60 verified the right key images 15-16 at log10 NFA -10 to -32, and each was doubted as a jump
// back from 30: uncertain, the tracker held at 30. Judged from the place last steered by, frames 56-60 are steered by
// at the right key images.
TEST_F(XfeatCorridorRun, AJumpBackIsJudgedFromWhereTheRunWasSteered) {
  // Measured without the tracker following the belief's guess after a jump it withholds, which keeps the tracker from
  // the route's end here as well (AJumpTheBeliefWithholdsIsNotTheTrackers).
  auto steered_after_dark = [&](const std::string& flags) {
    std::vector<std::pair<int, int>> after;
    for (const auto& steered : SteeredOnRepeat(0, 62, 0, " --verifier-seed 106 --no-jump-needs-belief" + flags)) {
      if (steered.first >= 54 && steered.first <= 60) after.push_back(steered);
    }
    return after;
  };
  const auto judged = steered_after_dark(""),
             from_tracker = steered_after_dark(" --no-judge-jump-back-from-steered-place");
  EXPECT_EQ(Far(judged), 0);
  EXPECT_GE(Right(judged), 4);
  EXPECT_GE(Right(judged), Right(from_tracker) + 4)
      << "the test no longer reaches the frames doubted as a jump back from the route's end";
}

// A relocalization away on little chance is doubted (docs/localize.md): repeat frames 44-58 at the verifier's seed 26,
// the corridor's dark stretch. Frame 48 was tracked at key image 14; frames 49-53 were uncertain, and frame 54 was
// relocalized at key image 30 (right: 14-15) on 21 matches at log10 NFA -3.1, its next key image at +0.5: steered by
// 16 key images from where the run last was. Doubted, it is uncertain.
TEST_F(XfeatCorridorRun, ARelocalizationAwayOnLittleChanceIsDoubted) {
  ExpectNoFarFrameButWithout(
      // The belief's step on, weighing as many positions on each side, mends this frame too: as before as well.
      " --no-doubt-relocalization-on-little-chance --step-on-by-belief-ahead 3", "frame 54 relocalized at key image 30",
      [&](const std::string& flags) { return SteeredOnRepeat(44, 58, KeyBefore(44), " --verifier-seed 26" + flags); });
}

// A frame tracked away on little chance is doubted (docs/localize.md, "A relocalization away on little chance is
// doubted"): repeat frames 40-56 at the verifier's seed 48, started at teach frame 40's key image. Frame 50 is tracked
// at key image 13; in the dark stretch frame 52 moves the tracker to key image 31 uncertain, and frame 53 was tracked
// there on 24 matches at log10 NFA -8.2, its next key image at +4.8 (right: 14-15). Doubted, it is uncertain.
TEST_F(XfeatCorridorRun, AFrameTrackedAwayOnLittleChanceIsDoubted) {
  ExpectNoFarFrameButWithout(
      " --no-doubt-relocalization-on-little-chance", "frame 53 tracked at key image 31",
      [&](const std::string& flags) { return SteeredOnRepeat(40, 56, KeyBefore(40), " --verifier-seed 48" + flags); });
}

// A frame tracked on from near where the run was steered is not doubted for its little chance (docs/localize.md, "A
// relocalization away on little chance is doubted"): repeat frames 44-60, started at teach frame 44's key image, at the
// verifier's seeds 8 and 13. Frame 50 is steered by at key image 13; frames 51-53 are the dark stretch's, uncertain,
// and the tracker starts frame 54 within two key images of 13. Frames 54-55 are tracked at key image 16 (in the whole
// corridor run at log10 NFA -2.7 to -7.3); three key images from 13 they were doubted, and 55 is right there (14-16).
TEST_F(XfeatCorridorRun, AFrameTrackedOnFromNearWhereTheRunWasSteeredIsNotDoubted) {
  for (const std::string seed : {"8", "13"}) {
    SCOPED_TRACE("verifier seed " + seed);
    const std::vector<std::pair<int, int>> steered = SteeredOnRepeat(44, 60, KeyBefore(44), " --verifier-seed " + seed);
    EXPECT_EQ(Far(steered), 0);
    const auto frame55 = std::find_if(steered.begin(), steered.end(), [](const auto& s) { return s.first == 55; });
    ASSERT_NE(frame55, steered.end()) << "repeat frame 55 is not steered by";
    EXPECT_EQ(Right({*frame55}), 1) << "repeat frame 55 is steered by at key image " << frame55->second;
  }
}

// A far place vouched for by its next key image needs the belief (docs/localize.md): repeat frames 20-60 started at key
// image 0 (bench/route_conditions.py's corridor from 20), at the verifier's seeds 87 and 165. The run was last steered
// by at key image 14 (frame 49); the dark frame 55 was relocalized at key image 29 (right: 14-16) at log10 NFA -7.5 to
// -9.3, on the strength of key image 30's -15.4, the belief holding 0.67-0.74 near it. Its own key image verifying by
// little beyond chance and the belief not singling the place out, it is uncertain, and the frames after it are steered
// by at the right key images 15-16 (at seed 165 they were uncertain: judged a jump back from 29).
TEST_F(XfeatCorridorRun, AFarPlaceVouchedForByItsNextKeyImageNeedsTheBelief) {
  for (const std::string seed : {"87", "165"}) {
    SCOPED_TRACE("verifier seed " + seed);
    const Steered vouched = SteeredOnRepeat(20, 60, 0, " --verifier-seed " + seed);
    // The belief's step on, weighing as many positions on each side, mends frame 55 too: as before as well.
    const Steered always = SteeredOnRepeat(
        20, 60, 0, " --verifier-seed " + seed + " --away-next-key-min-confidence 0 --step-on-by-belief-ahead 3");
    EXPECT_EQ(Far(vouched), 0);
    EXPECT_GE(Far(always), 1) << "the test no longer reaches the dark frame 55 placed at key image 29";
    EXPECT_GE(Right(vouched), Right(always));
  }
}

// A jump the belief withholds is not the tracker's (docs/localize.md): the corridor's repeat frames 0-62 started at key
// image 0, at the verifier's seed 256. After the dark frames 51-53 (uncertain), frame 54's relocalization took the
// tracker from key image 12 to 29 (the route's end; right: 14-15), while the belief withheld the frame and guessed key
// image 15. Reported there, the frame left the tracker at 29, and frame 55, compared
// with key images 29 and 30 alone, was steered by at 29. With the tracker at the guess, frames 55-60 are steered by at
// the right key images.
TEST_F(XfeatCorridorRun, AJumpTheBeliefWithholdsIsNotTheTrackers) {
  auto steered_after_dark = [&](const std::string& flags) {
    Steered after;
    for (const auto& steered : SteeredOnRepeat(0, 62, 0, " --verifier-seed 256" + flags)) {
      if (steered.first >= 54 && steered.first <= 60) after.push_back(steered);
    }
    return after;
  };
  const Steered at_guess = steered_after_dark(""), at_jump = steered_after_dark(" --no-jump-needs-belief");
  EXPECT_EQ(Far(at_guess), 0);
  EXPECT_GE(Far(at_jump), 1) << "the test no longer reaches a jump the belief withholds";
  EXPECT_GE(Right(at_guess), Right(at_jump) + 2);
}

}  // namespace
}  // namespace vmap::neural
