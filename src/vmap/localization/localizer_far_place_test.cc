// A far place along the route (more than two route positions from the tracked estimate): one frame pointing there
// does not carry the tracker away, two frames and the belief over the route (route_belief.h) do, and so does a frame
// after lost frames, as far as the robot could have gone; a far place one frame pointed at is asked again; frames
// that verify nothing after a confident run are carried by the belief.

#include <algorithm>
#include <cstdlib>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/localization/key_bracket.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localizer.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/localizer_test_util.h"

namespace vmap {
namespace {

using ::vmap::testing::Brackets;
using ::vmap::testing::DenseDriveMap;
using ::vmap::testing::GivenComparison;
using ::vmap::testing::LocalizeFramesOnDenseMap;
using ::vmap::testing::LocalizeOnDenseMap;
using ::vmap::testing::SidewaysDrive;

// The belief over the route (route_belief.h): a frame far from where the frames before it were is relocalized, but
// one frame is not enough to be sure of it (a chance match could look alike): it is uncertain, not to steer by,
// until the frames that follow confirm the place (a single chance match does not hold the robot back). Without the
// belief (min_confidence 0) it is steered by at once.
TEST(Localizer, AOneFrameJumpIsUncertainUntilTheFramesThatFollowConfirmIt) {
  const LocalizationMap& m = DenseDriveMap();
  for (const double min_confidence : {0.5, 0.0}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    ASSERT_EQ(options.belief.min_confidence, 0.5) << "the default";
    options.belief.min_confidence = min_confidence;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    for (int source_index : {1, 3, 5}) {
      const LocalizationResult r = LocalizeOnDenseMap(localizer, source_index, index++);
      EXPECT_NE(r.status, LocalizationStatus::kUncertain) << source_index;
      EXPECT_GT(r.confidence, 0.5) << source_index;
    }
    const LocalizationResult jumped = LocalizeOnDenseMap(localizer, 41, index++);
    if (min_confidence > 0) {
      // Uncertain: its key images are the best guess, where the belief holds the most (still at the start, where
      // the run of frames was: frame 41 sees the start's far plane too); the tracker goes on from frame 41's place.
      EXPECT_GT(jumped.confidence, 0.5) << "the belief's mass near its best guess";
    } else {
      EXPECT_TRUE(Brackets(m.map, 41, jumped.key)) << "at key " << jumped.key;
    }
    EXPECT_EQ(jumped.status, min_confidence > 0 ? LocalizationStatus::kUncertain : LocalizationStatus::kRelocalized);
    // The rule is named, for an audit of the run: the belief, which does not hold the place the tracker took the frame
    // to, gives its own guess, where no key image verifies.
    EXPECT_EQ(jumped.withheld_by, min_confidence > 0 ? Withholding::kBeliefMoved : Withholding::kNone);
    if (min_confidence > 0) EXPECT_EQ(LocalizationGuidance(jumped), "none: position uncertain (belief moved)");
    EXPECT_FALSE(min_confidence > 0 && MaySteerBy(jumped));
    // With the belief the tracker moves once two frames point at the new place and the belief agrees (frame 41 and
    // 43 see the start's far plane too, so it takes a frame or two more); steered by from there on.
    LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {43, 45, 47, 49}, &index);
    EXPECT_EQ(r.status, LocalizationStatus::kTracking);
    EXPECT_TRUE(Brackets(m.map, 49, r.key)) << "at key " << r.key;
    EXPECT_GT(r.confidence, 0.5);
  }
}

// A relocalization far from the tracked estimate (more than two route positions) is taken when two frames in a row
// point there and the belief agrees: one frame's chance match (across lighting a wrong key image often verifies as
// many matches as the right one) does not carry the tracker away. Frame 41 among the drive's first frames: the
// tracker stays at the start, and the next frame is tracked there. Without the belief (min_confidence 0) the
// tracker jumps at once and the next frame must be relocalized back.
TEST(Localizer, AFarRelocalizationOnOneFrameDoesNotCarryTheTrackerAway) {
  const LocalizationMap& m = DenseDriveMap();
  for (const double min_confidence : {0.5, 0.0}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    options.belief.min_confidence = min_confidence;
    // One motion step a frame: the frames are picked from the drive, their input indices are not its pace.
    options.belief.motion_steps_per_frame = 1;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizeFramesOnDenseMap(localizer, {1, 3, 5}, &index);
    const LocalizationResult far = LocalizeOnDenseMap(localizer, 41, index++);
    EXPECT_FALSE(min_confidence > 0 && MaySteerBy(far));
    const LocalizationResult back = LocalizeOnDenseMap(localizer, 7, index++);
    EXPECT_TRUE(Brackets(m.map, 7, back.key)) << "at key " << back.key;
    EXPECT_EQ(back.status, min_confidence > 0 ? LocalizationStatus::kTracking : LocalizationStatus::kRelocalized);
  }
  // Two frames pointing far, but the belief, weighed by their comparisons, still holds more near the start (frames 41
  // and 43 see the start's far plane too): the tracker stays, and the next frame at the start is tracked. Their
  // rankings do not see it (both put key images 19-22 first, the start's outside their best eight): weighed by them
  // (ORB's, rank_evidence) the belief follows the two frames there, as a far move on two frames should; the frame at
  // the start after them is then not steered by anywhere but at its place.
  for (const bool rank_evidence : {false, true}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    options.rank_evidence = rank_evidence;
    // One motion step a frame: the frames are picked from the drive, their input indices are not its pace.
    options.belief.motion_steps_per_frame = 1;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizeFramesOnDenseMap(localizer, {1, 3, 5, 41, 43}, &index);
    const LocalizationResult back = LocalizeOnDenseMap(localizer, 7, index++);
    if (!rank_evidence) {
      EXPECT_TRUE(Brackets(m.map, 7, back.key)) << "at key " << back.key;
      EXPECT_EQ(back.status, LocalizationStatus::kTracking);
    } else {
      EXPECT_TRUE(!MaySteerBy(back) || Brackets(m.map, 7, back.key)) << "steered by at key " << back.key;
    }
  }
}

// An uncertain frame's best guess is the belief's peak only when the frames before it had singled out a place: one
// frame's evidence does not make a flat belief a guess (across lighting XFeat verifies 17-32 matches at wrong key
// images, and a flat belief weighed by them alone put corridor_conditions' frames 7-8 at key image 28). Here the
// first frame is seen weakly at the start's key images (uncertain, the belief flat), the second strongly but not
// acceptably at the key images of frame 41's place while the start's still verify: uncertain at the start, where the
// tracker is, not at frame 41's place. The frames' comparisons are given (Localize's `ahead`).
TEST(Localizer, AFlatBeliefMakesNoBestGuessOfOneFramesEvidence) {
  const LocalizationMap& m = DenseDriveMap();
  const int count = static_cast<int>(m.map.key_images.size());
  const auto [far_before, far_after] = KeysAround(m.map, 41);
  ASSERT_GT(far_before, 10);
  // The frames' comparisons are given, their rankings are the images' own (the first frame's, of source 1, puts the
  // start first: the belief is no longer flat after it, and the second frame is tracked at the start, not doubted);
  // measured with the ranking not weighed, and with the defaults for what it guards.
  for (const bool rank_evidence : {false, true}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    options.rank_evidence = rank_evidence;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    auto localize = [&](int source_index, int index, bool far_seen) {
      std::vector<KeyComparison> given(count);
      for (int key = 0; key < count; ++key) {
        KeyComparison& c = given[key];
        c.key = key;
        c.similarity = 0.3;
        if (key <= 4) {
          c.matched = c.accepted = true;  // weakly: 20 verified matches, likely by chance
          c.num_verified = 20;
          c.log10_nfa = 3.0;
        } else if (far_seen && key >= far_before - 1 && key <= far_after + 1) {
          c.matched = true;  // many matches, refused (as the link share refuses another season's)
          c.num_verified = 100;
          c.log10_nfa = -40.0;
        }
      }
      ::vmap::testing::MemorySource source({SidewaysDrive().frames[source_index]}, {source_index});
      Frame frame = *source.Next();
      frame.index = index;
      return localizer.Localize(frame, *m.matcher->Extract(frame.gray), std::move(given));
    };
    const LocalizationResult first = localize(1, 0, false);
    ASSERT_EQ(first.status, LocalizationStatus::kUncertain) << first.confidence;
    ASSERT_LE(first.key, 4);
    const LocalizationResult second = localize(41, 1, true);
    if (!rank_evidence) {
      EXPECT_EQ(second.status, LocalizationStatus::kUncertain);
    }
    EXPECT_LE(second.key, 4) << "the tracker's key image, not the peak of one frame's evidence";
  }
}

// While frames are lost the robot moves on unseen: a relocalization after them may be further from the tracked
// estimate than two route positions, by up to `lookahead` key images a lost frame, and is taken at once (a route of
// michigan's five places, a place a frame, needs it). Here three frames see nothing, then the frame sees the key
// images 8 route positions on (and only them). The frames' comparisons are given (Localize's `ahead`).
TEST(Localizer, AfterLostFramesARelocalizationAsFarAsTheRobotCouldGoIsTakenAtOnce) {
  const LocalizationMap& m = DenseDriveMap();
  const int count = static_cast<int>(m.map.key_images.size());
  LocalizerOptions options = MapLocalizerOptions(m);
  // The comparisons given stand for the frame's own, verified in full (a far one would be made again with fewer
  // iterations).
  options.far_comparison_iterations = 0;
  // The seeing frame's input index jumps past the blind ones', which the lookahead by the pace would take for frames
  // driven and track to: the tracker is kept to its lookahead, so that the frame is the relocalization's.
  options.lookahead_by_pace = false;
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  int index = 0;
  LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5, 7, 9}, &index);
  ASSERT_EQ(r.status, LocalizationStatus::kTracking);
  const int far = r.route_position + 8;  // the route is the key images in order
  ASSERT_LT(far + 2, count);
  auto localize = [&](int source_index, bool sees) {
    std::vector<KeyComparison> given(count);
    for (int key = 0; key < count; ++key) {
      KeyComparison& c = given[key];
      c.key = key;
      if (sees && std::abs(key - far) <= 1) {
        c.matched = c.accepted = true;
        c.num_verified = 200;
        c.similarity = 0.5;
        c.log10_nfa = -40.0;
      }
    }
    ::vmap::testing::MemorySource source({SidewaysDrive().frames[source_index]}, {source_index});
    Frame frame = *source.Next();
    frame.index = index++;
    return localizer.Localize(frame, *m.matcher->Extract(frame.gray), std::move(given));
  };
  for (int blind = 0; blind < 3; ++blind) r = localize(11 + 2 * blind, false);
  ASSERT_FALSE(MaySteerBy(r));
  r = localize(2 * far + 1, true);
  EXPECT_EQ(r.status, LocalizationStatus::kRelocalized);
  EXPECT_LE(std::abs(r.route_position - far), 1) << "at route position " << r.route_position;
}

// A far relocalization one frame pointed at is asked again on the next frame, even when that frame still verifies
// enough at the tracked key image to keep it: otherwise the second frame that rule 1 of the belief needs never
// comes while the tracked key image keeps half its link's matches (redkitchen's hand-held camera held key image 69
// for 15 frames past a run of blurred key images that verify less). Here frame A verifies 0.45 of the tracked key
// image's link (less than `recheck_link_share`) and some at the key images 8 route positions on; frame B 0.8 of
// the link and more there. The frames' comparisons are given (Localize's `ahead`).
TEST(Localizer, AFarPlaceOneFramePointedAtIsAskedAgainOnTheNextFrame) {
  const LocalizationMap& m = DenseDriveMap();
  const int count = static_cast<int>(m.map.key_images.size());
  LocalizerOptions options = MapLocalizerOptions(m);
  // The comparisons given stand for the frame's own, verified in full (a far one would be made again with fewer
  // iterations).
  options.far_comparison_iterations = 0;
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  int index = 0;
  LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5}, &index);
  ASSERT_EQ(r.status, LocalizationStatus::kTracking);
  const int p = r.route_position;  // the route is the key images in order
  const int far = p + 8;
  ASSERT_LT(far + 2, count);
  int link_verified = 0;  // the fewest verified matches of a link of key image p (the localizer's reference)
  for (const Link& link : m.map.links) {
    if (link.from_key == p || link.to_key == p) {
      link_verified = link_verified > 0 ? std::min(link_verified, link.num_verified) : link.num_verified;
    }
  }
  ASSERT_GT(link_verified, 10);
  // Seen as in the same season: the tracked key image beyond chance, the next one weakly (it does not take the
  // tracker on), the far ones by `far_share` of the link at `far_log10_nfa`.
  auto localize = [&](double tracked_share, double far_share, double far_log10_nfa) {
    std::vector<KeyComparison> given(count);
    for (int key = 0; key < count; ++key) given[key] = GivenComparison(key, false, 0, 0.0);
    given[p] = GivenComparison(p, true, static_cast<int>(tracked_share * link_verified), -40.0);
    given[p + 1] = GivenComparison(p + 1, true, static_cast<int>(0.3 * link_verified), -5.0);
    for (int key = far - 1; key <= far + 1; ++key) {
      given[key] = GivenComparison(key, true, static_cast<int>(far_share * link_verified), far_log10_nfa);
    }
    return LocalizeOnDenseMap(localizer, 2 * far + 1, index++, std::move(given));
  };
  r = localize(0.45, 0.6, -12.0);
  ASSERT_EQ(r.route_position, p) << "one frame does not carry the tracker away (rule 1)";
  r = localize(0.8, 1.0, -40.0);
  EXPECT_LE(std::abs(r.route_position - far), 1) << "at route position " << r.route_position;
  EXPECT_EQ(r.status, LocalizationStatus::kRelocalized);
}

// The belief moves the estimate (LocalizerOptions::belief.window): frames that verify against no key image (here
// the drive's frames through fog and glare) after a run of frames that singled out a place are not lost but placed
// at the belief's peak, carried along the route by its motion model, as a best guess not to steer by
// (uncertain); the next frame that sees the scene is tracked from there. Without it (window 0) they are lost.
TEST(Localizer, FramesThatVerifyNothingAfterAConfidentRunAreCarriedByTheBelief) {
  const LocalizationMap& m = DenseDriveMap();
  cv::Mat noise(SidewaysDrive().frames[0].size(), CV_8UC3);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  for (const int window : {2, 0}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    ASSERT_EQ(options.belief.window, 2) << "the default";
    options.belief.window = window;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5, 7, 9}, &index);
    ASSERT_EQ(r.status, LocalizationStatus::kTracking);
    const int tracked_position = r.route_position;
    for (int blind = 0; blind < 3; ++blind) {
      // The drive's next frames seen through fog and glare: little of the scene is left, and nothing verifies.
      cv::Mat foggy;
      cv::addWeighted(SidewaysDrive().frames[11 + blind], 0.25, noise, 0.75, 0.0, foggy);
      Frame frame;
      frame.index = index++;
      cv::cvtColor(foggy, frame.gray, cv::COLOR_BGR2GRAY);
      frame.color = foggy;
      r = localizer.Localize(frame, *DenseDriveMap().matcher->Extract(frame.gray));
      EXPECT_FALSE(MaySteerBy(r)) << window;
      if (window > 0) {
        EXPECT_EQ(r.status, LocalizationStatus::kUncertain) << blind;
        EXPECT_EQ(r.withheld_by, Withholding::kBeliefMoved) << "moved by the belief, nothing verified";
        EXPECT_GE(r.confidence, 0.5) << blind;
        EXPECT_GE(r.route_position, tracked_position - 1) << "carried along the route, not lost";
        EXPECT_LE(r.route_position, tracked_position + 4);
      } else {
        EXPECT_EQ(r.status, LocalizationStatus::kLost) << blind;
      }
    }
    r = LocalizeOnDenseMap(localizer, 13, index++);
    EXPECT_EQ(r.status, LocalizationStatus::kTracking) << window;
    EXPECT_TRUE(Brackets(m.map, 13, r.key)) << "at key " << r.key;
  }
}

// A blind frame (black: a lens cap, a tunnel, a camera's first frames) has no features to verify with, which says
// nothing of where the robot is: it is lost where the run was, and the belief keeps what the run's frames said. Taken
// as evidence, nothing verified weighed against the tracked key image and the belief's peak, which trails the tracker,
// took the estimate back a key image.
TEST(Localizer, ABlindFrameIsLostWhereTheRunWasAndWeighsNothing) {
  const LocalizationMap& m = DenseDriveMap();
  Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  int index = 0;
  LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5, 7, 9, 11, 13}, &index);
  ASSERT_EQ(r.status, LocalizationStatus::kTracking);
  const int tracked_position = r.route_position;
  const double confidence = r.confidence;
  const cv::Mat black = cv::Mat::zeros(SidewaysDrive().frames[0].size(), CV_8UC3);
  for (int blind = 0; blind < 2; ++blind) {
    Frame frame;
    frame.index = index++;
    cv::cvtColor(black, frame.gray, cv::COLOR_BGR2GRAY);
    frame.color = black;
    r = localizer.Localize(frame, *m.matcher->Extract(frame.gray));
    EXPECT_EQ(r.status, LocalizationStatus::kLost) << blind;
    EXPECT_EQ(r.route_position, tracked_position) << blind;
    EXPECT_GE(r.confidence, 0.9 * confidence) << blind;
  }
  r = LocalizeOnDenseMap(localizer, 15, index++);
  EXPECT_EQ(r.status, LocalizationStatus::kTracking);
  EXPECT_TRUE(Brackets(m.map, 15, r.key)) << "at key " << r.key;
}

}  // namespace
}  // namespace vmap
