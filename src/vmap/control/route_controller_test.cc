#include "vmap/control/route_controller.h"

#include <cmath>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/zoomed_matches.h"

namespace vmap {
namespace {

// A straight route of four key images, 2 s apart, with a 500 px camera.
TaughtRoute StraightRoute() {
  TaughtRoute route;
  route.keys = {0, 1, 2, 3};
  for (int k = 0; k < 3; ++k) {
    TaughtSegment segment;
    segment.from_key = k;
    segment.to_key = k + 1;
    segment.duration = 2.0;
    segment.yaw_change = 0.0;
    route.segments.push_back(segment);
  }
  route.focal_px = 500.0;
  return route;
}

// The straight route with its teach odometry: key images 1 m apart along x, taken 2 s apart.
TaughtRoute MetricStraightRoute() {
  TaughtRoute route = StraightRoute();
  for (int k = 0; k < 4; ++k) route.key_poses.push_back({10.0 + 2.0 * k, 1.0 * k, 0.0, 0.0});
  for (int i = 0; i <= 30; ++i) route.path.push_back({10.0 + 0.2 * i, 0.1 * i, 0.0, 0.0});
  for (TaughtSegment& segment : route.segments) segment.length = 1.0;
  return route;
}

LocalizationResult Tracked(int key, double heading_deg) {
  LocalizationResult result;
  result.status = LocalizationStatus::kTracking;
  result.key = key;
  result.route_position = key;
  result.next_key = key < 3 ? key + 1 : -1;
  result.heading_deg = heading_deg;
  result.heading_px = std::tan(heading_deg * M_PI / 180.0) * 500.0;
  result.progress = 0.5;
  result.to_key.accepted = true;
  return result;
}

LocalizationResult Lost() {
  LocalizationResult result;
  result.status = LocalizationStatus::kLost;
  result.key = 1;  // the last estimate, not to steer by
  result.next_key = 2;
  result.heading_deg = 5.0;
  return result;
}

ControllerOptions NoRateLimits() {
  ControllerOptions options;
  options.max_acceleration = 100.0;
  options.max_angular_acceleration = 100.0;
  return options;
}

// A controller that saw a frame 0.1 s before the test's first: a first frame's command is the robot's first from rest,
// which the accelerations limit to none; after it, NoRateLimits' accelerations allow any command.
RouteController Running(const TaughtRoute& route, const ControllerOptions& options) {
  RouteController controller(route, options);
  controller.Update(-0.1, Lost());
  return controller;
}

TEST(RouteController, StartsOnlyOnceLocalized) {
  RouteController controller(StraightRoute(), NoRateLimits());
  ControlStep step = controller.Update(0.0, Lost());
  EXPECT_EQ(step.state, ControllerState::kStarting);
  EXPECT_FALSE(step.localized);
  EXPECT_EQ(step.command.linear, 0.0);
  EXPECT_EQ(step.command.angular, 0.0);
  step = controller.Update(0.1, Tracked(1, 0.0));
  EXPECT_EQ(step.state, ControllerState::kFollowing);
  EXPECT_TRUE(step.localized);
  EXPECT_EQ(step.route_position, 1);  // started mid-route
  EXPECT_EQ(step.target_key, 2);
  EXPECT_DOUBLE_EQ(step.command.linear, 0.3);
  EXPECT_DOUBLE_EQ(step.command.angular, 0.0);
}

TEST(RouteController, BearnavTurnsAgainstTheHeading) {
  ControllerOptions options = NoRateLimits();
  options.law = ControlLaw::kBearnav;
  options.heading_gain = 2.0;
  RouteController controller = Running(StraightRoute(), options);
  // The scene appears 5 degrees right: the robot points left and turns right (clockwise, w < 0).
  const ControlStep step = controller.Update(0.0, Tracked(0, 5.0));
  EXPECT_EQ(step.steering, "bearnav");
  EXPECT_NEAR(step.heading_offset, 5.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(step.command.angular, -2.0 * 5.0 * M_PI / 180.0, 1e-12);
}

TEST(RouteController, TaughtTurnRateIsFedForward) {
  TaughtRoute route = StraightRoute();
  route.segments[1].yaw_change = 0.4;  // 0.4 rad left in 2 s at the taught pace (options.speed)
  ControllerOptions options = NoRateLimits();
  options.law = ControlLaw::kBearnav;
  // Half-way along the stretch (progress 0.5), on the taught path: the next key image looks 0.2 rad further left
  // than the robot (heading offset -0.2 rad), as it should; only the taught rate turns the robot.
  const double on_path_deg = -0.2 * 180.0 / M_PI;
  RouteController controller = Running(route, options);
  ControlStep step = controller.Update(0.0, Tracked(1, on_path_deg));
  EXPECT_NEAR(step.command.angular, 0.2, 1e-12);
  // Pointing 0.1 rad further left than that: the heading term turns it back.
  RouteController off = Running(route, options);
  EXPECT_NEAR(off.Update(0.0, Tracked(1, on_path_deg + 0.1 * 180.0 / M_PI)).command.angular, 0.2 - 0.1, 1e-12);
  // With the length from odometry: curvature times speed.
  route.segments[1].length = 1.0;
  RouteController with_length = Running(route, options);
  step = with_length.Update(0.0, Tracked(1, on_path_deg));
  EXPECT_DOUBLE_EQ(step.command.linear, 0.5);  // the taught speed, 1 m in 2 s
  EXPECT_NEAR(step.command.angular, 0.4 / 1.0 * 0.5, 1e-12);
}

TEST(RouteController, ServoSteersToTheKeyImagesLineWhenTheTranslationIsKnown) {
  RouteController controller = Running(StraightRoute(), NoRateLimits());
  LocalizationResult result = Tracked(0, 0.0);
  // The next key image 1.5 m ahead and 0.4 m to the left, looking as the robot does.
  result.translation_known = true;
  result.to_next.pose.valid = true;
  result.to_next.pose.R = cv::Matx33d::eye();
  const cv::Vec3d centre(-0.4, 0.0, 1.5);
  result.to_next.pose.t = -centre / cv::norm(centre);
  const ControlStep step = controller.Update(0.0, result);
  EXPECT_EQ(step.steering, "servo");
  EXPECT_GT(step.bearing, 0.0);
  EXPECT_LT(step.line_angle, 0.0);
  EXPECT_GT(step.command.angular, 0.0);  // turns left, towards the line
  // Unknown translation: the heading law.
  result.translation_known = false;
  RouteController again(StraightRoute(), NoRateLimits());
  EXPECT_EQ(again.Update(0.0, result).steering, "bearnav");
}

TEST(RouteController, TrackerFollowsTheTaughtPathWhereTheRouteIsMetric) {
  const TaughtRoute route = MetricStraightRoute();
  ASSERT_TRUE(route.metric());
  ControllerOptions options = NoRateLimits();
  options.law = ControlLaw::kTracker;
  RouteController controller = Running(route, options);
  // The first frame places the estimate on the path at the key image, turned as the heading says:
  // the robot points 10 degrees left of the path and turns right.
  ControlStep step = controller.Update(0.0, Tracked(1, 10.0));
  EXPECT_EQ(step.steering, "tracker");
  EXPECT_NEAR(step.lateral_estimate, 0.0, 1e-9);
  EXPECT_NEAR(step.heading_error_estimate, 10.0 * M_PI / 180.0, 1e-9);
  EXPECT_LT(step.command.angular, 0.0);
  // Half a metre driven at that heading (odometry) while the localization is lost, the estimate is left of the
  // path by as much as the robot.
  const double yaw = 10.0 * M_PI / 180.0;
  const OdometrySample start{0.0, 0.0, 0.0, yaw};
  controller.Reset();
  controller.Update(0.0, Tracked(1, 10.0), &start);
  const OdometrySample later{0.5, 0.5 * std::cos(yaw), 0.5 * std::sin(yaw), yaw};
  step = controller.Update(0.5, Lost(), &later);
  EXPECT_EQ(step.state, ControllerState::kLost);
  EXPECT_NEAR(step.lateral_estimate, 0.5 * std::sin(yaw), 1e-3);
  // A route without teach odometry is not metric: the tracker steers as the servo law does.
  RouteController without(StraightRoute(), options);
  EXPECT_EQ(without.Update(0.0, Tracked(1, 0.0)).steering, "bearnav");
}

TEST(RouteController, TurnsOnTheSpotWhenFacingFarOff) {
  RouteController controller = Running(StraightRoute(), NoRateLimits());
  const ControlStep step = controller.Update(0.0, Tracked(0, -60.0));
  EXPECT_EQ(step.state, ControllerState::kTurning);
  EXPECT_EQ(step.command.linear, 0.0);
  EXPECT_GT(step.command.angular, 0.0);  // points right of the key image: turns left
}

TEST(RouteController, LostSlowsToAStopAndResumes) {
  ControllerOptions options = NoRateLimits();
  options.lost_stop_seconds = 1.0;
  RouteController controller = Running(StraightRoute(), options);
  controller.Update(0.0, Tracked(1, 0.0));
  ControlStep step = controller.Update(0.5, Lost());
  EXPECT_EQ(step.state, ControllerState::kLost);
  EXPECT_NEAR(step.command.linear, 0.15, 1e-12);  // half-way to a stop
  EXPECT_DOUBLE_EQ(step.command.angular, 0.0);    // the taught turn rate, not the lost frame's heading
  step = controller.Update(1.5, Lost());
  EXPECT_EQ(step.command.linear, 0.0);
  step = controller.Update(1.6, Tracked(1, 0.0));
  EXPECT_EQ(step.state, ControllerState::kFollowing);
  EXPECT_DOUBLE_EQ(step.command.linear, 0.3);
}

// A clock that goes back (sim time restarted, a bag played again) takes nothing from the time lost: the robot lost
// for 0.5 s before a reset of 100 s has slowed half-way, and stops 0.5 s after it, not 100 s later.
TEST(RouteController, AClockThatGoesBackKeepsTheTimeLost) {
  ControllerOptions options = NoRateLimits();
  options.lost_stop_seconds = 1.0;
  RouteController controller = Running(StraightRoute(), options);
  controller.Update(100.0, Tracked(1, 0.0));
  EXPECT_NEAR(controller.Update(100.5, Lost()).command.linear, 0.15, 1e-12);
  EXPECT_NEAR(controller.Update(0.0, Lost()).command.linear, 0.15, 1e-12);  // no time passed at the reset
  EXPECT_NEAR(controller.Update(0.25, Lost()).command.linear, 0.075, 1e-12);
  EXPECT_EQ(controller.Update(0.6, Lost()).command.linear, 0.0);
  // The search starts 2 s after the last usable frame, counted across the reset.
  RouteController searching(StraightRoute(), NoRateLimits());
  searching.Update(50.0, Lost());
  searching.Update(51.0, Lost());
  EXPECT_NE(searching.Update(1.0, Lost()).steering, "search");
  EXPECT_NE(searching.Update(1.9, Lost()).steering, "search");
  EXPECT_EQ(searching.Update(2.1, Lost()).steering, "search");
}

TEST(RouteController, SearchesForTheRouteWhenStandingUnlocalized) {
  RouteController controller(StraightRoute(), NoRateLimits());
  ControlStep step;
  double t = 0.0;
  for (; t < 1.95; t += 0.1) EXPECT_EQ(controller.Update(t, Lost()).command.angular, 0.0) << t;  // waits 2 s
  step = controller.Update(t, Lost());
  EXPECT_EQ(step.state, ControllerState::kStarting);
  EXPECT_EQ(step.steering, "search");
  EXPECT_EQ(step.command.linear, 0.0);
  EXPECT_DOUBLE_EQ(step.command.angular, 0.3);  // left first
  // 30 degrees at 0.3 rad/s take 1.75 s; then it sweeps back to the right.
  double last_angular = step.command.angular;
  int flips = 0;
  double flip_time = 0.0;
  for (t += 0.1; t < 6.0; t += 0.1) {
    step = controller.Update(t, Lost());
    if (step.command.angular != last_angular && flips++ == 0) flip_time = t;
    last_angular = step.command.angular;
  }
  EXPECT_GE(flips, 1);
  EXPECT_NEAR(flip_time, 2.0 + 1.8, 0.15);
  // Localized: the search ends.
  step = controller.Update(t, Tracked(0, 0.0));
  EXPECT_EQ(step.state, ControllerState::kFollowing);
  EXPECT_NE(step.steering, "search");
}

TEST(RouteController, AccelerationIsLimited) {
  ControllerOptions options;
  options.max_acceleration = 0.5;
  RouteController controller(StraightRoute(), options);
  controller.Update(0.0, Lost());
  ControlStep step = controller.Update(0.1, Tracked(1, 0.0));
  EXPECT_NEAR(step.command.linear, 0.05, 1e-12);
  step = controller.Update(0.2, Tracked(1, 0.0));
  EXPECT_NEAR(step.command.linear, 0.10, 1e-12);
}

TEST(RouteController, StopsWhereTheGoalLooksAsLargeAsInItsKeyImage) {
  RouteController controller = Running(StraightRoute(), NoRateLimits());
  LocalizationResult at_goal = Tracked(3, 0.0);
  at_goal.to_key.verified = testing::ZoomedMatches(0.9);  // still 10 % smaller: drive on, at the goal speed
  ControlStep step = controller.Update(0.0, at_goal);
  EXPECT_EQ(step.state, ControllerState::kFollowing);
  EXPECT_NEAR(step.goal_log_scale, std::log(0.9), 1e-4);
  EXPECT_DOUBLE_EQ(step.command.linear, 0.3 * 0.5);
  at_goal.to_key.verified = testing::ZoomedMatches(0.99);
  step = controller.Update(0.1, at_goal);
  EXPECT_EQ(step.state, ControllerState::kFollowing);  // the median of the last three frames: one is not enough
  step = controller.Update(0.15, at_goal);
  EXPECT_EQ(step.state, ControllerState::kReachedGoal);
  EXPECT_EQ(step.command.linear, 0.0);
  // Stays stopped whatever comes next, until Reset.
  EXPECT_EQ(controller.Update(0.2, Tracked(1, 0.0)).state, ControllerState::kReachedGoal);
  controller.Reset();
  EXPECT_EQ(controller.Update(0.3, Lost()).state, ControllerState::kStarting);
}

// The loop's failed repeats with the odometry 5 % too long stopped 0.31-0.42 m short: at the goal's end of a
// deep scene the goal's points are 2 % smaller 0.4 m before it. The map's last link says how much they grow over
// the last stretch; the goal waits for all but goal_scale_share of that.
TEST(RouteController, WhereTheGoalsSceneIsDeepTheGoalWaitsForMostOfItsGrowth) {
  TaughtRoute route = StraightRoute();
  route.segments.back().log_scale = std::log(0.92);  // the goal's scene grows by 8 % over the last stretch
  RouteController controller(route, NoRateLimits());
  // Three frames at the goal each time: the goal is judged on the median of the last three.
  auto state_after_three = [](RouteController& controller, double zoom, double time) {
    LocalizationResult at_goal = Tracked(3, 0.0);
    at_goal.to_key.verified = testing::ZoomedMatches(zoom);
    controller.Update(time, at_goal);
    controller.Update(time + 0.1, at_goal);
    return controller.Update(time + 0.2, at_goal).state;
  };
  EXPECT_EQ(state_after_three(controller, 0.985, 0.0), ControllerState::kFollowing);  // 1.5 %: within 2 %, but a
                                                                                      // fifth of the growth remains
  EXPECT_EQ(state_after_three(controller, 0.995, 1.0), ControllerState::kReachedGoal);
  // A shallow scene (the last stretch's growth 30 %): the 2 % tolerance is the stricter, as without the link's.
  route.segments.back().log_scale = std::log(0.7);
  RouteController shallow(route, NoRateLimits());
  EXPECT_EQ(state_after_three(shallow, 0.975, 0.0), ControllerState::kFollowing);
  EXPECT_EQ(state_after_three(shallow, 0.985, 1.0), ControllerState::kReachedGoal);
  // goal_scale_share 0: the tolerance alone.
  ControllerOptions options = NoRateLimits();
  options.goal_scale_share = 0.0;
  route.segments.back().log_scale = std::log(0.92);
  RouteController tolerance_only(route, options);
  EXPECT_EQ(state_after_three(tolerance_only, 0.985, 0.0), ControllerState::kReachedGoal);
}

TEST(RouteController, OneStrayScaleAtTheGoalDoesNotStopTheRobot) {
  RouteController controller(StraightRoute(), NoRateLimits());
  LocalizationResult at_goal = Tracked(3, 0.0);
  for (double zoom : {0.9, 0.9, 1.0, 0.9}) {
    at_goal.to_key.verified = testing::ZoomedMatches(zoom);
    EXPECT_EQ(controller.Update(0.0, at_goal).state, ControllerState::kFollowing) << zoom;
  }
}

// Across seasons the localizer placed nearly every frame of the last stretch at the key image before the goal,
// never at the goal, and the robot drove 0.3-0.5 m past it: the goal's scene is judged against the goal as the
// next key image too, where the frame verifies enough matches with it.
TEST(RouteController, AFrameStillBeforeTheGoalStopsWhereTheGoalLooksAsLarge) {
  auto state_after_three = [](double zoom, int verified) {
    RouteController controller(StraightRoute(), NoRateLimits());
    LocalizationResult before_goal = Tracked(2, 0.0);  // next_key 3, the goal
    before_goal.to_next.matched = true;
    before_goal.to_next.verified = testing::ZoomedMatches(zoom);
    before_goal.to_next.verified.resize(verified);
    before_goal.to_next.num_verified = verified;
    ControlStep step;
    for (int i = 0; i < 3; ++i) step = controller.Update(0.1 * i, before_goal);
    return step.state;
  };
  EXPECT_EQ(state_after_three(0.99, 60), ControllerState::kReachedGoal);
  EXPECT_EQ(state_after_three(0.9, 60), ControllerState::kFollowing);   // still 10 % smaller
  EXPECT_EQ(state_after_three(0.99, 10), ControllerState::kFollowing);  // too few matches to judge by
  // Two stretches before the goal: not judged.
  RouteController controller(StraightRoute(), NoRateLimits());
  LocalizationResult earlier = Tracked(1, 0.0);
  earlier.to_next.matched = true;
  earlier.to_next.verified = testing::ZoomedMatches(1.0);
  earlier.to_next.num_verified = 60;
  for (int i = 0; i < 3; ++i) EXPECT_EQ(controller.Update(0.1 * i, earlier).state, ControllerState::kFollowing);
}

TEST(RouteController, KeyImagesOffTheRouteAreNotSteeredBy) {
  TaughtRoute route = StraightRoute();
  RouteController controller(route, NoRateLimits());
  LocalizationResult elsewhere = Tracked(1, 0.0);
  elsewhere.key = 7;
  EXPECT_EQ(controller.Update(0.0, elsewhere).state, ControllerState::kStarting);
}

TEST(RouteController, BadOptionsAndRoutesAreRefused) {
  ControllerOptions options;
  options.speed = std::nan("");
  EXPECT_THROW(RouteController(StraightRoute(), options), OptionError);
  // k_b > 0 > k_l, the servo law's stability condition: a gain of 0 is refused too.
  for (const auto& [bearing, line] : std::vector<std::pair<double, double>>{{1.5, 0.5}, {1.5, 0.0}, {0.0, -0.6}}) {
    options = {};
    options.bearing_gain = bearing;
    options.line_gain = line;
    EXPECT_THROW(RouteController(StraightRoute(), options), OptionError) << bearing << " " << line;
  }
  options = {};
  options.speed = 5.0;
  options.max_speed = 1.0;
  EXPECT_THROW(RouteController(StraightRoute(), options), OptionError) << "a speed above the largest";
  TaughtRoute no_camera = StraightRoute();
  no_camera.focal_px = std::nan("");
  EXPECT_THROW(RouteController(no_camera, ControllerOptions{}), OptionError);
  TaughtRoute one_key;
  one_key.keys = {4};
  one_key.focal_px = 500.0;
  try {
    RouteController(one_key, ControllerOptions{});
    ADD_FAILURE() << "a route of one key image was taken";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("key image 4 alone: give a goal other than its start"), std::string::npos)
        << error.what();
  }
}

// The accelerations hold from rest: the first command and one at a stamp that did not advance change nothing (the first
// was 1.0 m/s from standstill whatever the limits, 20 times them).
TEST(RouteController, TheFirstCommandAndOneAtAStampThatDidNotAdvanceKeepTheAccelerations) {
  RouteController controller(StraightRoute(), ControllerOptions());
  ControlStep step = controller.Update(5.0, Tracked(1, 30.0));
  EXPECT_EQ(step.state, ControllerState::kFollowing);
  EXPECT_EQ(step.command.linear, 0.0);
  EXPECT_EQ(step.command.angular, 0.0);
  step = controller.Update(5.1, Tracked(1, 30.0));
  EXPECT_NEAR(step.command.linear, 0.05, 1e-12);
  EXPECT_NEAR(step.command.angular, -0.3, 1e-12);  // 3 rad/s^2 for 0.1 s
  for (double stamp : {5.1, 4.0}) {                // the same stamp again, and one before it
    const ControlStep again = controller.Update(stamp, Tracked(1, -30.0));
    EXPECT_NEAR(again.command.linear, 0.05, 1e-12) << stamp;
    EXPECT_NEAR(again.command.angular, -0.3, 1e-12) << stamp;
  }
}

// A lost robot slows down from the speed it was given: one turning on the spot stays on the spot (it drove forward at
// up to 0.18 m/s), and a stamp from before its last usable frame never speeds it up (it drove at 1.8 times its speed).
TEST(RouteController, ALostRobotSlowsDownFromTheSpeedItWasGiven) {
  RouteController turning = Running(StraightRoute(), NoRateLimits());
  EXPECT_EQ(turning.Update(0.0, Tracked(1, 60.0)).state, ControllerState::kTurning);
  for (double t = 0.1; t < 1.5; t += 0.1) {
    const ControlStep step = turning.Update(t, Lost());
    EXPECT_EQ(step.state, ControllerState::kLost);
    EXPECT_EQ(step.command.linear, 0.0) << t;
  }
  RouteController driving = Running(StraightRoute(), NoRateLimits());
  EXPECT_DOUBLE_EQ(driving.Update(10.0, Tracked(1, 0.0)).command.linear, 0.3);
  const ControlStep earlier = driving.Update(9.0, Lost());
  EXPECT_EQ(earlier.state, ControllerState::kLost);
  EXPECT_LE(earlier.command.linear, 0.3);
}

// What is no number never reaches the wheels: a NaN time is refused, an odometry sample holding one is ignored (one
// made every later turn rate NaN).
TEST(RouteController, InputsThatAreNoNumbersNeverMakeACommandThatIsNone) {
  const TaughtRoute route = MetricStraightRoute();
  ControllerOptions options = NoRateLimits();
  options.law = ControlLaw::kTracker;
  RouteController controller = Running(route, options);
  EXPECT_THROW(controller.Update(std::nan(""), Tracked(1, 0.0)), std::invalid_argument);
  const double nan = std::nan("");
  const OdometrySample odometry[] = {
      {0.0, 0.0, 0.0, 0.0}, {0.1, nan, 0.0, 0.0}, {0.2, 0.06, 0.0, nan}, {0.3, 0.09, 0.0, 0.0}};
  for (int i = 0; i < 4; ++i) {
    for (const LocalizationResult& result : {Tracked(1, 5.0), Lost()}) {
      const ControlStep step =
          controller.Update(0.1 * i + (result.status == LocalizationStatus::kLost ? 0.05 : 0.0), result, &odometry[i]);
      EXPECT_TRUE(std::isfinite(step.command.linear) && std::isfinite(step.command.angular)) << i;
    }
  }
}

// An odometry step no robot drives in the time (a glitch of 1e300 m, a reset by 5 m) is no motion: steering went on
// as NaN, then 0, for the rest of the run, and a jump forward put the tracker's estimate past the goal, which ended
// the run half-way.
TEST(RouteController, AnOdometryJumpIsNoMotion) {
  const TaughtRoute route = MetricStraightRoute();
  ControllerOptions options = NoRateLimits();
  options.law = ControlLaw::kTracker;
  for (const double jump : {1e300, 5.0}) {
    RouteController controller = Running(route, options);
    double x = 0.0;
    for (int i = 0; i < 30; ++i) {
      const double t = 0.1 * i;
      x += 0.03;
      const OdometrySample odometry{t, i >= 10 ? x + jump : x, 0.0, 0.0};
      const ControlStep step = controller.Update(t, Tracked(1, 10.0), &odometry);
      ASSERT_TRUE(std::isfinite(step.command.angular)) << jump << " " << i;
      EXPECT_EQ(step.state, ControllerState::kFollowing) << jump << " " << i;
      EXPECT_LT(step.command.angular, 0.0) << jump << " " << i;  // still steers towards the path
    }
  }
}

// At the goal the robot stops within the decelerations, and the controller says it reached the goal meanwhile (the
// stop was one step, 6 m/s^2 at twice the speed, which put the simulated robot short of where a base stops).
TEST(RouteController, TheGoalStopKeepsTheDecelerations) {
  ControllerOptions options;
  options.max_acceleration = 0.5;
  RouteController controller(StraightRoute(), options);
  LocalizationResult at_goal = Tracked(3, 0.0);
  at_goal.to_key.verified = testing::ZoomedMatches(0.9);
  double t = 0.0;
  for (; t < 1.0; t += 0.1) controller.Update(t, at_goal);  // up to the goal speed, 0.15 m/s
  at_goal.to_key.verified = testing::ZoomedMatches(1.0);
  std::vector<double> speeds;
  for (; speeds.empty() || speeds.back() > 0.0; t += 0.1) {
    const ControlStep step = controller.Update(t, at_goal);
    if (step.state == ControllerState::kReachedGoal) speeds.push_back(step.command.linear);
    ASSERT_LT(t, 3.0);
  }
  ASSERT_EQ(speeds.size(), 3u);
  EXPECT_NEAR(speeds[0], 0.10, 1e-9);
  EXPECT_NEAR(speeds[1], 0.05, 1e-9);
  EXPECT_EQ(speeds[2], 0.0);
}

}  // namespace
}  // namespace vmap
