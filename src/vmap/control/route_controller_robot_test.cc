// What a real robot's drivers and teach runs give the controller besides clean frames: odometry that drops out, stops
// commanded from outside the controller, routes driven backwards and teach runs that stood at their goal.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/control/route_controller.h"
#include "vmap/testing/zoomed_matches.h"

namespace vmap {
namespace {

constexpr double kStep = 0.1;  // s between frames

// Key images 1 m apart along x, taught at 0.3 m/s, the teach odometry every 0.1 m (a metric route).
TaughtRoute MetricStraight(int keys) {
  TaughtRoute route;
  constexpr double kTaughtSpeed = 0.3;
  for (int k = 0; k < keys; ++k) {
    route.keys.push_back(k);
    route.key_poses.push_back({k / kTaughtSpeed, 1.0 * k, 0.0, 0.0});
  }
  for (int k = 0; k + 1 < keys; ++k) {
    TaughtSegment segment;
    segment.from_key = k;
    segment.to_key = k + 1;
    segment.duration = 1.0 / kTaughtSpeed;
    segment.length = 1.0;
    segment.yaw_change = 0.0;
    route.segments.push_back(segment);
  }
  for (int i = 0; i <= 10 * (keys - 1); ++i) route.path.push_back({0.1 * i / kTaughtSpeed, 0.1 * i, 0.0, 0.0});
  route.focal_px = 500.0;
  return route;
}

// A frame at x along the route, tracked at the nearest key image before the last, heading straight on.
LocalizationResult TrackedAt(double x, int keys) {
  LocalizationResult result;
  result.status = LocalizationStatus::kTracking;
  result.key = std::clamp(static_cast<int>(std::floor(x + 0.5)), 0, keys - 2);
  result.route_position = result.key;
  result.next_key = result.key + 1;
  result.heading_deg = 0.0;
  result.heading_px = 0.0;
  result.progress = std::clamp(x - result.key, 0.0, 1.0);
  return result;
}

// A robot on a plane that drives exactly what it is commanded.
struct Robot {
  double x = 0.0, y = 0.0, yaw = 0.0, time = 0.0;
  void Drive(const VelocityCommand& command) {
    x += command.linear * kStep * std::cos(yaw + 0.5 * command.angular * kStep);
    y += command.linear * kStep * std::sin(yaw + 0.5 * command.angular * kStep);
    yaw += command.angular * kStep;
    time += kStep;
  }
  OdometrySample Odometry() const { return {time, x, y, yaw}; }
};

ControllerOptions TrackerLaw() {
  ControllerOptions options;
  options.law = ControlLaw::kTracker;
  return options;
}

// Where the tracker puts the robot along the path, less where it is, 30 frames after the odometry came back from a
// dropout of `gap` frames.
double ArcErrorAfterAnOdometryDropout(int gap) {
  constexpr int kKeys = 6;
  RouteController controller(MetricStraight(kKeys), TrackerLaw());
  Robot robot;
  constexpr int kDropoutStart = 20;
  double error = 0.0;
  for (int frame = 0; frame < kDropoutStart + gap + 30; ++frame) {
    const OdometrySample odometry = robot.Odometry();
    const bool dropped = frame >= kDropoutStart && frame < kDropoutStart + gap;
    const ControlStep step = controller.Update(robot.time, TrackedAt(robot.x, kKeys), dropped ? nullptr : &odometry);
    error = step.arc_estimate - robot.x;
    robot.Drive(step.command);
  }
  return error;
}

// The odometry was taken once over the gap and once more by the commands: 0.15 m ahead per 5 frames of dropout.
TEST(RouteControllerOnARobot, AnOdometryDropoutIsNotDrivenTwice) {
  const double without = ArcErrorAfterAnOdometryDropout(0);
  for (int gap : {5, 10, 15}) EXPECT_NEAR(ArcErrorAfterAnOdometryDropout(gap), without, 0.05) << gap << " frames";
}

TEST(RouteControllerOnARobot, AStopFromOutsideStartsTheNextCommandFromRest) {
  constexpr int kKeys = 6;
  RouteController controller(MetricStraight(kKeys), TrackerLaw());
  Robot robot;
  ControlStep step;
  for (int frame = 0; frame < 30; ++frame) {
    step = controller.Update(robot.time, TrackedAt(robot.x, kKeys));
    robot.Drive(step.command);
  }
  ASSERT_GT(step.command.linear, 0.25);  // at cruise speed
  const double arc_before = step.arc_estimate;
  // A quiet camera: the host stops the robot, which stands for 2 s.
  controller.Stopped();
  robot.time += 2.0;
  step = controller.Update(robot.time, TrackedAt(robot.x, kKeys));
  EXPECT_EQ(step.command.linear, 0.0);  // from rest, as a first command
  // The 2 s stood are not driven at the last command (0.6 m at 0.3 m/s); without odometry the last frame's 3 cm
  // before the stop are not known either.
  EXPECT_NEAR(step.arc_estimate, arc_before, 0.04);
  robot.Drive(step.command);
  step = controller.Update(robot.time, TrackedAt(robot.x, kKeys));
  EXPECT_LE(step.command.linear, controller.options().max_acceleration * kStep + 1e-9);
}

// A route followed backwards (`vmap route --from 3 --to 0`) reverses with the camera facing as taught: the goal's
// scene looks larger before the goal and shrinks to its size there.
TEST(RouteControllerOnARobot, ARouteDrivenBackwardsStopsWhereTheGoalLooksAsLarge) {
  TaughtRoute route;
  route.keys = {3, 2, 1, 0};
  for (int i = 0; i < 3; ++i) {
    TaughtSegment segment;
    segment.from_key = route.keys[i];
    segment.to_key = route.keys[i + 1];
    segment.backwards = true;
    segment.duration = 3.0;
    segment.yaw_change = 0.0;
    segment.log_scale = std::log(1.25);  // the goal's scene, seen from the stretch's start, 25 % larger
    route.segments.push_back(segment);
  }
  route.focal_px = 500.0;
  auto state_after_three = [&](double zoom) {
    RouteController controller(route, ControllerOptions{});
    LocalizationResult before_goal;  // a stretch before the goal, which the frame sees as its next key image
    before_goal.status = LocalizationStatus::kTracking;
    before_goal.key = 1;
    before_goal.route_position = 2;
    before_goal.next_key = 0;
    before_goal.heading_deg = 0.0;
    before_goal.progress = 0.5;
    before_goal.to_key.accepted = true;
    before_goal.to_next.matched = true;
    before_goal.to_next.verified = testing::ZoomedMatches(zoom);
    before_goal.to_next.num_verified = static_cast<int>(before_goal.to_next.verified.size());
    ControlStep step;
    for (int i = 0; i < 3; ++i) step = controller.Update(kStep * i, before_goal);
    return step;
  };
  const ControlStep far = state_after_three(1.25);
  EXPECT_EQ(far.state, ControllerState::kFollowing);
  EXPECT_LT(far.command.linear, 0.0);  // reversing
  EXPECT_EQ(state_after_three(1.1).state, ControllerState::kFollowing);
  EXPECT_EQ(state_after_three(1.005).state, ControllerState::kReachedGoal);
}

// The fallback stop (an estimate well past the end of the path) reads the direction the teach run arrived in; a
// robot taught by hand stood at its goal for the last samples, which give no direction.
TEST(RouteControllerOnARobot, APathThatStoodAtItsGoalStillStopsARobotPastIt) {
  constexpr int kKeys = 6;
  for (int standing : {0, 5}) {
    TaughtRoute route = MetricStraight(kKeys);
    const OdometrySample end = route.path.back();
    for (int i = 1; i <= standing; ++i) route.path.push_back({end.timestamp + 0.1 * i, end.x, end.y, end.yaw});
    route.key_poses.back().timestamp = route.path.back().timestamp;
    RouteController controller(route, TrackerLaw());
    Robot robot;
    ControlStep step;
    // Frames never show the goal's scale: the localizer places them on the last stretch to the end.
    while (step.state != ControllerState::kReachedGoal && robot.time < 60.0) {
      const OdometrySample odometry = robot.Odometry();
      step = controller.Update(robot.time, TrackedAt(robot.x, kKeys), &odometry);
      robot.Drive(step.command);
    }
    EXPECT_EQ(step.state, ControllerState::kReachedGoal) << standing << " samples standing";
    EXPECT_LT(robot.x, end.x + 1.0) << standing << " samples standing";
  }
}

}  // namespace
}  // namespace vmap
