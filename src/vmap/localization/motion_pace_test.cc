#include "vmap/localization/motion_pace.h"

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

namespace vmap {
namespace {

TEST(MotionPace, TheStepsFollowTheMapsSpacingAndTheRunsFrameStep) {
  // Key images about 3 teach frames apart (the spacing the model was fitted on): one step a frame.
  EXPECT_DOUBLE_EQ(TeachFramesPerPosition({0, 2, 6, 9, 13, 23}), 4.6);
  EXPECT_DOUBLE_EQ(TeachFramesPerPosition({0, 2, 5, 8, 12}), 3.0);
  EXPECT_EQ(MotionStepsPerFrame(1, 3.0), 1);
  EXPECT_EQ(MotionStepsPerFrame(1, 2.3), 1);
  // A video's sparse map, or a frame at an unknown step: never fewer than one.
  EXPECT_EQ(MotionStepsPerFrame(1, 82.0), 1);
  EXPECT_EQ(MotionStepsPerFrame(0, 3.0), 1);
  EXPECT_EQ(MotionStepsPerFrame(-5, 3.0), 1);
  // A map of every place (--tau 1), and a sparse map run at a third of the frames (--stride 3): a key image a frame.
  EXPECT_EQ(MotionStepsPerFrame(1, 1.0), 3);
  EXPECT_EQ(MotionStepsPerFrame(3, 3.0), 3);
  // Bounded; a route of one key image has no spacing.
  EXPECT_EQ(MotionStepsPerFrame(100, 1.0), kMaxMotionSteps);
  EXPECT_EQ(MotionStepsPerFrame(2e9, 1e-9), kMaxMotionSteps);
  EXPECT_EQ(MotionStepsPerFrame(std::numeric_limits<double>::infinity(), 1.0), kMaxMotionSteps);
  EXPECT_DOUBLE_EQ(TeachFramesPerPosition({7}), 0.0);
  EXPECT_EQ(MotionStepsPerFrame(1, 0.0), 1);
  // A route driven backwards through the map spaces its key images the same.
  EXPECT_DOUBLE_EQ(TeachFramesPerPosition({9, 6, 3, 0}), 3.0);
}

// The tracker looks past the next key image as far as the run went since the frame before: further than its lookahead
// only where key images crowd within the teach frames passed (rccar_room's fast turn: a key image every frame).
TEST(MotionPace, TheLookaheadReachesTheKeyImagesCrowdedWithinTheFramesPassed) {
  // Key images 3-4 teach frames apart, then one every frame from route position 4 (input frames 13 to 18).
  const std::vector<int> route = {0, 3, 6, 10, 13, 14, 15, 16, 17, 18, 22, 26};
  const std::vector<double> no_times(route.size(), -1.0);
  MotionPace pace(route, no_times);
  EXPECT_EQ(pace.Lookahead(3, 2), 2) << "before a first frame nothing was passed";
  pace.Steps(0, -1.0);
  EXPECT_EQ(pace.Lookahead(3, 2), 2) << "the run's first frame: how far it went is not known";
  // Every frame (one teach frame a frame): the lookahead, wherever it is.
  pace.Steps(1, -1.0);
  for (int position = 0; position < static_cast<int>(route.size()); ++position) {
    EXPECT_EQ(pace.Lookahead(position, 2), 2) << position;
  }
  EXPECT_EQ(pace.Lookahead(0, 1), 1);
  EXPECT_EQ(pace.Lookahead(3, 1), 2) << "a lookahead of one reaches the key image a frame after the next";
  EXPECT_FALSE(pace.PassedLookahead(3, 2)) << "a frame a frame: the tracker's own rules";
  // Every third frame: three teach frames a frame. Where the key images crowd, the three after the next one (at 14,
  // 15 and 16, within three frames of 13) are reached; where they do not, the lookahead stays.
  pace.Steps(4, -1.0);
  EXPECT_EQ(pace.Lookahead(3, 2), 4);
  EXPECT_EQ(pace.Lookahead(6, 2), 3) << "17 and 18 after the next one, 16: the last crowded ones";
  EXPECT_EQ(pace.Lookahead(0, 2), 2);
  EXPECT_EQ(pace.Lookahead(10, 2), 2) << "the next key image is the route's last";
  EXPECT_EQ(pace.Lookahead(11, 2), 2) << "at the route's end";
  EXPECT_EQ(pace.Lookahead(-1, 2), 2) << "no estimate";
  // The whole lookahead passed: the key images after the next one within the three frames, where they crowd and also
  // where they lie three frames apart; not at the route's end.
  EXPECT_TRUE(pace.PassedLookahead(3, 2));
  EXPECT_TRUE(pace.PassedLookahead(0, 2));
  EXPECT_FALSE(pace.PassedLookahead(9, 2)) << "26 is four frames after the next one, 22";
  EXPECT_FALSE(pace.PassedLookahead(10, 2));
  // A long gap in the input: bounded.
  pace.Steps(104, -1.0);
  EXPECT_EQ(pace.Lookahead(0, 2), kMaxMotionSteps);
  // By time: three teach frames' time a frame (the teach run at 10 frames/s), whatever the input indices say.
  std::vector<double> times;
  for (const int frame : route) times.push_back(frame * 0.1);
  MotionPace timed(route, times);
  timed.Steps(0, 5.0);
  timed.Steps(1, 5.31);
  EXPECT_EQ(timed.Lookahead(3, 2), 4);
  timed.Steps(2, 5.41);
  EXPECT_EQ(timed.Lookahead(3, 2), 2);
  EXPECT_FALSE(timed.PassedLookahead(3, 2));
  // The time between frames jitters: 0.19 s at 0.1 s a teach frame is two frames (rccar_room every second frame).
  timed.Steps(3, 5.60);
  EXPECT_EQ(timed.Lookahead(3, 2), 3);
  EXPECT_TRUE(timed.PassedLookahead(3, 2));
  // A fixed pace says nothing of the teach frames passed.
  MotionPace fixed(route, no_times, 3);
  fixed.Steps(0, -1.0);
  fixed.Steps(3, -1.0);
  EXPECT_EQ(fixed.Lookahead(3, 2), 2);
  EXPECT_FALSE(fixed.PassedLookahead(3, 2));
}

TEST(MotionPace, TheTeachRunsTimeIsKnownOnlyWhereItRunsOneWayAlongTheRoute) {
  EXPECT_NEAR(TeachSecondsPerPosition({10.0, 10.3, 10.6, 11.2}), 0.4, 1e-12);
  EXPECT_DOUBLE_EQ(TeachSecondsPerPosition({0.9, 0.6, 0.3, 0.0}), 0.3) << "a route backwards through the map";
  EXPECT_DOUBLE_EQ(TeachSecondsPerPosition({0.0, 0.3, -1.0, 0.9}), 0.0) << "a key image without a time";
  EXPECT_DOUBLE_EQ(TeachSecondsPerPosition({0.0, 0.3, 0.2, 0.9}), 0.0) << "key images of two recordings";
  EXPECT_DOUBLE_EQ(TeachSecondsPerPosition({0.0, 0.3, 0.3, 0.9}), 0.0) << "two key images at one time";
  EXPECT_DOUBLE_EQ(TeachSecondsPerPosition({0.0, std::numeric_limits<double>::quiet_NaN()}), 0.0);
  EXPECT_DOUBLE_EQ(TeachSecondsPerPosition({0.0, std::numeric_limits<double>::infinity()}), 0.0);
  EXPECT_DOUBLE_EQ(TeachSecondsPerPosition({4.0}), 0.0);
}

// The teach run at 10 frames a second, a key image every third frame (the model's own pace: one step a frame).
MotionPace TeachRunPace(bool with_times, int fixed_steps = 0) {
  const std::vector<int> indices = {0, 3, 6, 9, 12, 15};
  std::vector<double> times;
  for (const int i : indices) times.push_back(with_times ? 0.1 * i : -1.0);
  return MotionPace(indices, times, fixed_steps);
}

// A repeat recorded at a third of the teach run's frame rate, or localized by a node that keeps one frame in three:
// its input indices run on by one a frame, its times by 0.3 s, a key image passed every frame.
std::vector<int> StepsOfARunAtAThirdOfTheFrameRate(MotionPace pace, bool with_times) {
  std::vector<int> steps;
  for (int frame = 0; frame < 5; ++frame) steps.push_back(pace.Steps(frame, with_times ? 0.3 * frame : -1.0));
  return steps;
}

TEST(MotionPace, TheTimeBetweenFramesSaysHowFarTheRunWentWhateverItsFrameRate) {
  EXPECT_EQ(StepsOfARunAtAThirdOfTheFrameRate(TeachRunPace(true), true), (std::vector<int>{1, 3, 3, 3, 3}));
  // Without the times of either, its input indices say one frame: one step, a third of what it passed.
  EXPECT_EQ(StepsOfARunAtAThirdOfTheFrameRate(TeachRunPace(true), false), (std::vector<int>{1, 1, 1, 1, 1}));
  EXPECT_EQ(StepsOfARunAtAThirdOfTheFrameRate(TeachRunPace(false), true), (std::vector<int>{1, 1, 1, 1, 1}));
  // A fixed count is that count, but on the run's first frame.
  EXPECT_EQ(StepsOfARunAtAThirdOfTheFrameRate(TeachRunPace(true, 2), true), (std::vector<int>{1, 2, 2, 2, 2}));

  // At the teach run's frame rate, by time or by index: one step a frame; a frame after a stretch not recorded (a
  // logging gap, the input index one on) moves as far as that stretch went.
  MotionPace pace = TeachRunPace(true);
  EXPECT_EQ(pace.Steps(20, 2.0), 1);
  EXPECT_EQ(pace.Steps(21, 2.1), 1);
  EXPECT_EQ(pace.Steps(22, 2.4), 3);
  EXPECT_EQ(pace.Steps(23, 2.5), 1);
  EXPECT_EQ(pace.Steps(24, 3.7), kMaxMotionSteps);
  // A clock that goes back (a restarted recording): the input index, two frames on.
  EXPECT_EQ(pace.Steps(26, 1.0), 2);
  // A frame without a time, and the one after it: the input index.
  EXPECT_EQ(pace.Steps(29, -1.0), 3);
  EXPECT_EQ(pace.Steps(30, 1.9), 1);
  // A new run: its first frame one step.
  pace.Reset();
  EXPECT_EQ(pace.Steps(90, 9.0), 1);
  EXPECT_EQ(pace.Steps(91, 9.3), 3);
}

TEST(MotionPace, TheTeachOdometrysDistanceIsKnownWhereItCoversTheRouteOneWay) {
  EXPECT_NEAR(TeachMetresPerPosition({1.0, 1.5, 2.2, 2.5}), 0.5, 1e-12);
  EXPECT_NEAR(TeachMetresPerPosition({2.5, 2.2, 1.5, 1.0}), 0.5, 1e-12) << "a route backwards through the map";
  EXPECT_NEAR(TeachMetresPerPosition({1.0, 1.0, 2.0}), 0.5, 1e-12) << "two key images where the robot turned in place";
  const double none = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NEAR(TeachMetresPerPosition({none, 1.0, none, 2.0, none}), 0.5, 1e-12)
      << "key images the odometry does not cover: the others space the route";
  EXPECT_DOUBLE_EQ(TeachMetresPerPosition({none, 1.0, none}), 0.0) << "one key image covered";
  EXPECT_DOUBLE_EQ(TeachMetresPerPosition({none, none}), 0.0);
  EXPECT_DOUBLE_EQ(TeachMetresPerPosition({1.0, 2.0, 1.5}), 0.0) << "key images of two recordings";
  EXPECT_DOUBLE_EQ(TeachMetresPerPosition({3.0, 3.0}), 0.0) << "an odometry that did not move";
  EXPECT_DOUBLE_EQ(TeachMetresPerPosition({3.0}), 0.0);
}

OdometrySample Pose(double x, double y = 0.0) {
  OdometrySample pose;
  pose.x = x;
  pose.y = y;
  return pose;
}

// A robot that repeats the route faster or slower than it was taught, its camera at the teach run's frame rate: the
// times and indices say a frame's worth of the teach run, its odometry how far it went.
TEST(MotionPace, TheDistanceDrivenSaysHowFarTheRunWentWhateverItsSpeed) {
  MotionPace pace = TeachRunPace(true);                    // a key image every 0.3 s, every third frame
  pace.SetTeachDistances({0.0, 0.3, 0.6, 0.9, 1.2, 1.5});  // at 1 m/s: 0.3 m a key image
  ASSERT_TRUE(pace.by_distance());
  EXPECT_EQ(pace.Steps(0, 0.0, Pose(0.0)), 1) << "a run's first frame";
  EXPECT_EQ(pace.Steps(1, 0.1, Pose(0.3)), 3) << "three times the teach speed";
  EXPECT_EQ(pace.Steps(2, 0.2, Pose(0.3, 0.2)), 2) << "sideways, a straight line";
  EXPECT_EQ(pace.Steps(3, 0.3, Pose(0.3, 0.2)), 1) << "standing still: the one step every frame takes";
  // A frame without odometry, and the one after it: by time.
  EXPECT_EQ(pace.Steps(4, 0.4, std::nullopt), 1);
  EXPECT_EQ(pace.Steps(5, 0.7, Pose(5.0)), 3);
  EXPECT_EQ(pace.Steps(6, 0.8, Pose(5.6)), 6);
  // A new run: its first frame one step, whatever the odometry says of the frame before.
  pace.Reset();
  EXPECT_EQ(pace.Steps(7, 0.9, Pose(9.0)), 1);
  EXPECT_EQ(pace.Steps(8, 1.0, Pose(9.1)), 1);

  // Without the teach odometry (or where it does not run one way along the route), by time as before.
  MotionPace by_time = TeachRunPace(true);
  by_time.SetTeachDistances({0.0, 0.3, 0.2, 0.9, 1.2, 1.5});
  EXPECT_FALSE(by_time.by_distance());
  EXPECT_EQ(by_time.Steps(0, 0.0, Pose(0.0)), 1);
  EXPECT_EQ(by_time.Steps(1, 0.1, Pose(0.3)), 1);
  // A fixed count is that count.
  MotionPace fixed = TeachRunPace(true, 2);
  fixed.SetTeachDistances({0.0, 0.3, 0.6, 0.9, 1.2, 1.5});
  EXPECT_EQ(fixed.Steps(0, 0.0, Pose(0.0)), 1);
  EXPECT_EQ(fixed.Steps(1, 0.1, Pose(0.9)), 2);
}

TEST(MotionPace, TheMetresDrivenAddUpWithinAStretchOfFramesWithOdometry) {
  MotionPace pace = TeachRunPace(true);
  pace.SetTeachDistances({0.0, 0.3, 0.6, 0.9, 1.2, 1.5});
  EXPECT_FALSE(pace.metres_driven()) << "before any frame";
  pace.Steps(0, 0.0, Pose(1.0));
  const int stretch = pace.driving_stretch();
  EXPECT_DOUBLE_EQ(pace.metres_driven().value(), 0.0) << "a stretch begins at its first frame";
  pace.Steps(1, 0.1, Pose(1.3));
  pace.Steps(2, 0.2, Pose(1.3, 0.4));
  EXPECT_NEAR(pace.metres_driven().value(), 0.7, 1e-9) << "the straight lines between the frames, summed";
  pace.Steps(3, 0.3, Pose(1.3, 0.4));
  EXPECT_NEAR(pace.metres_driven().value(), 0.7, 1e-9) << "standing still";
  EXPECT_EQ(pace.driving_stretch(), stretch);
  // A frame without odometry ends the stretch: how far the robot went meanwhile is not known.
  pace.Steps(4, 0.4, std::nullopt);
  EXPECT_FALSE(pace.metres_driven());
  pace.Steps(5, 0.5, Pose(3.0));
  EXPECT_NE(pace.driving_stretch(), stretch);
  EXPECT_DOUBLE_EQ(pace.metres_driven().value(), 0.0);
  pace.Steps(6, 0.6, Pose(3.2));
  EXPECT_NEAR(pace.metres_driven().value(), 0.2, 1e-9);
  // A pose that is not a number, and a new run, begin a stretch too.
  const int before_nan = pace.driving_stretch();
  pace.Steps(7, 0.7, Pose(std::nan("")));
  EXPECT_FALSE(pace.metres_driven());
  pace.Steps(8, 0.8, Pose(4.0));
  EXPECT_GT(pace.driving_stretch(), before_nan);
  EXPECT_DOUBLE_EQ(pace.metres_driven().value(), 0.0);
  const int before_reset = pace.driving_stretch();
  pace.Reset();
  pace.Steps(9, 0.9, Pose(4.5));
  EXPECT_GT(pace.driving_stretch(), before_reset);
  EXPECT_DOUBLE_EQ(pace.metres_driven().value(), 0.0);
}

// Where on the teach run the distance driven puts the robot: counted from a key image, kept within a stretch of
// odometry, taken onto a segment of the route.
TEST(MotionPace, TheDistanceDrivenPutsTheRobotOnTheTeachRun) {
  MotionPace pace = TeachRunPace(true);
  pace.SetTeachDistances({10.0, 10.3, std::nan(""), 10.9, 11.2, 11.5});  // key image 2 not covered
  pace.Steps(0, 0.0, Pose(0.0));
  EXPECT_FALSE(pace.teach_metres_driven()) << "not counted yet";
  pace.CountDrivenFrom(1);
  EXPECT_DOUBLE_EQ(pace.teach_metres_driven().value(), 10.3);
  pace.Steps(1, 0.1, Pose(0.5));
  EXPECT_NEAR(pace.teach_metres_driven().value(), 10.8, 1e-9);
  EXPECT_EQ(pace.NearestPosition(10.8), 3) << "the uncovered key image is never nearest";
  EXPECT_EQ(pace.NearestPosition(-4.0), 0);
  EXPECT_EQ(pace.NearestPosition(99.0), 5);
  EXPECT_EQ(pace.DrivenPosition(), 3);
  // Taken onto the segment from key image 3 to 4 (10.9 to 11.2): moved to its nearer end, the count then driven on.
  pace.PlaceDrivenOnSegment(3);
  EXPECT_DOUBLE_EQ(pace.teach_metres_driven().value(), 10.9);
  pace.Steps(2, 0.2, Pose(0.6));
  EXPECT_NEAR(pace.teach_metres_driven().value(), 11.0, 1e-9);
  pace.PlaceDrivenOnSegment(3);
  EXPECT_NEAR(pace.teach_metres_driven().value(), 11.0, 1e-9) << "on the segment: stays";
  pace.PlaceDrivenOnSegment(5);  // the last key image: a segment of its own place
  EXPECT_DOUBLE_EQ(pace.teach_metres_driven().value(), 11.5);
  // Not covered: not counted from, nor placed on.
  EXPECT_FALSE(pace.Covers(2));
  EXPECT_FALSE(pace.Covers(-1));
  EXPECT_FALSE(pace.Covers(6));
  pace.PlaceDrivenOnSegment(2);
  EXPECT_DOUBLE_EQ(pace.teach_metres_driven().value(), 11.5);
  pace.CountDrivenFrom(2);
  EXPECT_FALSE(pace.teach_metres_driven());
  // A stretch of odometry that ends ends the count.
  pace.CountDrivenFrom(0);
  pace.Steps(3, 0.3, std::nullopt);
  pace.Steps(4, 0.4, Pose(0.9));
  EXPECT_FALSE(pace.teach_metres_driven());

  // A route backwards through the teach run: the teach metres shrink as the robot drives on.
  MotionPace backwards = TeachRunPace(true);
  backwards.SetTeachDistances({1.5, 1.2, 0.9, 0.6, 0.3, 0.0});
  backwards.Steps(0, 0.0, Pose(0.0));
  backwards.CountDrivenFrom(0);
  backwards.Steps(1, 0.1, Pose(0.0, 0.4));
  EXPECT_NEAR(backwards.teach_metres_driven().value(), 1.1, 1e-9);
  EXPECT_EQ(backwards.NearestPosition(1.1), 1);
  // Without the teach odometry nothing is counted.
  MotionPace by_time = TeachRunPace(true);
  by_time.Steps(0, 0.0, Pose(0.0));
  by_time.CountDrivenFrom(0);
  EXPECT_FALSE(by_time.teach_metres_driven());
  EXPECT_EQ(by_time.NearestPosition(0.0), -1);
  EXPECT_EQ(by_time.DrivenPosition(), -1);
}

}  // namespace
}  // namespace vmap
