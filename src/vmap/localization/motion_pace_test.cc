#include "vmap/localization/motion_pace.h"

#include <limits>
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

}  // namespace
}  // namespace vmap
