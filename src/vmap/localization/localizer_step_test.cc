// Steps along the route on one frame's matches (a key image on or back, or two on) that the belief over the route
// (route_belief.h) must agree with: two key images that look alike to a frame are not told apart by its matches.

#include <gtest/gtest.h>

#include "vmap/localization/localization_map.h"
#include "vmap/localization/localizer.h"
#include "vmap/testing/localizer_test_util.h"

namespace vmap {
namespace {

using ::vmap::testing::DenseDriveMap;
using ::vmap::testing::GivenComparison;
using ::vmap::testing::LocalizeFramesOnDenseMap;
using ::vmap::testing::LocalizeOnDenseMap;

// A frame the tracker moves two key images on (LocalizerOptions::lookahead 2) because the second verifies a match or
// two more than the first goes back to the first when the belief holds more on the segment after it: one key image a
// frame is likelier than two (the motion model), and the key image past the second does not see the frame. Without
// the belief (window 0) the frame stays two key images on. The frame's comparisons are given (Localize's `ahead`).
TEST(Localizer, TwoKeyImagesOnInOneFrameNeedsTheBeliefToAgree) {
  const LocalizationMap& m = DenseDriveMap();
  for (const int window : {2, 0}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    options.belief.window = window;
    // The comparisons given stand for the frame's own, verified in full (a far one would be made again with fewer
    // iterations).
    options.far_comparison_iterations = 0;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5}, &index);
    ASSERT_EQ(r.status, LocalizationStatus::kTracking);
    const int p = r.route_position;
    ASSERT_LT(p + 3, static_cast<int>(m.map.key_images.size()));
    // The frame no longer sees key image p, sees p + 1 and p + 2 alike (p + 2 by two matches more), not p + 3.
    auto given = [](int key, bool seen, int verified) { return GivenComparison(key, seen, verified, -10.0); };
    r = LocalizeOnDenseMap(
        localizer, 7, index++,
        {given(p, false, 0), given(p + 1, true, 60), given(p + 2, true, 62), given(p + 3, false, 0)});
    EXPECT_EQ(r.status, LocalizationStatus::kTracking) << window;
    EXPECT_EQ(r.route_position, window > 0 ? p + 1 : p + 2) << window;
  }
}

// A frame the tracker moves one key image on because the next verifies a match or two more than its key image goes
// back when the belief holds more on the segment before its key image than on the segment after the next one: two key
// images that look alike to the frame (one teach frame apart, or across seasons) are not told apart by one frame's
// matches, and the run of frames before it says where it is. Without the belief (window 0) the frame moves on.
TEST(Localizer, OneKeyImageOnNeedsTheBeliefNotToHoldMoreBehind) {
  const LocalizationMap& m = DenseDriveMap();
  for (const int window : {2, 0}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    options.belief.window = window;
    // One motion step a frame: the frames are picked from the drive, their input indices are not its pace.
    options.belief.motion_steps_per_frame = 1;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5}, &index);
    ASSERT_EQ(r.status, LocalizationStatus::kTracking);
    const int p = r.route_position;
    ASSERT_GE(p, 1);
    ASSERT_LT(p + 2, static_cast<int>(m.map.key_images.size()));
    // The frame sees key images p and p + 1 alike and weakly, as across seasons (p + 1 by two matches more, log10 NFA
    // -1), not p + 2.
    auto given = [](int key, bool seen, int verified) { return GivenComparison(key, seen, verified, -1.0); };
    r = LocalizeOnDenseMap(localizer, 7, index++, {given(p, true, 20), given(p + 1, true, 22), given(p + 2, false, 0)});
    EXPECT_EQ(r.status, LocalizationStatus::kTracking) << window;
    EXPECT_EQ(r.route_position, window > 0 ? p : p + 1) << window;
  }
}

// The same when the key image left does not verify (LocalizerOptions::hold_unearned_step_on): across lighting the
// tracker moves on to a key image ahead that verifies weakly while the one it held is refused, and the belief puts the
// frame behind (corridor_conditions frame 49: guided on to key image 21 while the belief held 0.016 there; the next
// frame stepped back). The frame stays on the segment before the key image reached, tracking: that key image, now
// `next_key`, verified. Without the rule the frame moves on.
TEST(Localizer, AStepOnPastAKeyImageThatDoesNotVerifyNeedsTheBeliefToo) {
  const LocalizationMap& m = DenseDriveMap();
  for (const bool hold : {true, false}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    options.hold_unearned_step_on = hold;
    // One motion step a frame: the frames are picked from the drive, their input indices are not its pace.
    options.belief.motion_steps_per_frame = 1;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5}, &index);
    ASSERT_EQ(r.status, LocalizationStatus::kTracking);
    const int p = r.route_position;
    ASSERT_GE(p, 1);
    ASSERT_LT(p + 2, static_cast<int>(m.map.key_images.size()));
    // Key image p verifies as many matches as p + 1 but at the edge of chance (refused), p + 1 just within it.
    KeyComparison at_key = GivenComparison(p, true, 22, 0.5);
    at_key.accepted = false;
    r = LocalizeOnDenseMap(localizer, 7, index++,
                           {at_key, GivenComparison(p + 1, true, 22, -1.0), GivenComparison(p + 2, false, 0, 0.0)});
    EXPECT_EQ(r.status, LocalizationStatus::kTracking) << hold;
    EXPECT_EQ(r.route_position, hold ? p : p + 1) << hold;
  }
}

// A step back needs the belief too (LocalizerOptions::step_back_needs_belief), the mirror of a step on: a frame the
// tracker moves back because the key image behind verifies a few more matches, less likely by chance, returns when
// the belief holds more past the key image left than before the one reached and the key image left verifies (two key
// images that look alike are not told apart by one frame; corridor_conditions frame 64 stepped back from key image 26
// to 25 on 25 matches at log10 NFA -0.3 against 21 at 0.8 while the belief held 0.95 past 26). Without the rule the
// frame steps back.
TEST(Localizer, AStepBackNeedsTheBeliefNotToHoldMorePastTheKeyImageLeft) {
  const LocalizationMap& m = DenseDriveMap();
  for (const bool needs_belief : {true, false}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    options.step_back_needs_belief = needs_belief;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5}, &index);
    ASSERT_EQ(r.status, LocalizationStatus::kTracking);
    const int p = r.route_position;
    ASSERT_GE(p, 2);
    ASSERT_LT(p + 1, static_cast<int>(m.map.key_images.size()));
    // Key images p - 1 and p both verify weakly, p - 1 by a few matches more at a lower log10 NFA; p + 1 does not.
    r = LocalizeOnDenseMap(localizer, 5, index++,
                           {GivenComparison(p - 2, false, 0, 0.0), GivenComparison(p - 1, true, 25, -0.5),
                            GivenComparison(p, true, 21, 0.5), GivenComparison(p + 1, false, 0, 0.0)});
    EXPECT_EQ(r.status, LocalizationStatus::kTracking) << needs_belief;
    EXPECT_EQ(r.route_position, needs_belief ? p : p - 1) << needs_belief;
  }
}

}  // namespace
}  // namespace vmap
