// The tracker law's pieces: locating a pose on a taught path, the path-following turn rate, and the pose
// estimate from bearings to key images.

#include "vmap/control/path_tracker.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/control/route_pose_estimator.h"
#include "vmap/control/route_tracking.h"
#include "vmap/testing/zoomed_matches.h"

namespace vmap {
namespace {

// Samples 0.1 m apart along the x axis, from 0 to `length` metres, one a second.
std::vector<OdometrySample> StraightPath(double length) {
  std::vector<OdometrySample> samples;
  for (int i = 0; i * 0.1 <= length + 1e-9; ++i) samples.push_back({double(i), 0.1 * i, 0.0, 0.0});
  return samples;
}

TEST(TaughtPath, LocatesAPoseBesideAStraightPath) {
  const TaughtPath path(StraightPath(4.0));
  EXPECT_NEAR(path.length(), 4.0, 1e-9);
  const PathLocation at = path.Locate({1.25, 0.2, 0.1}, 0.0, path.length());
  EXPECT_NEAR(at.s, 1.25, 1e-9);
  EXPECT_NEAR(at.lateral, 0.2, 1e-9);  // left of the taught heading
  EXPECT_NEAR(at.heading_error, 0.1, 1e-9);
  EXPECT_NEAR(at.curvature, 0.0, 1e-9);
  EXPECT_NEAR(path.Locate({2.0, -0.3, 0.0}, 0.0, path.length()).lateral, -0.3, 1e-9);
  EXPECT_NEAR(path.ArcAtTime(12.5), 1.25, 1e-9);
}

TEST(TaughtPath, CurvatureOfALeftArcAndTheWindowOfALoop) {
  // A full circle of radius 1 m driven counter-clockwise: the start and the end are the same place.
  std::vector<OdometrySample> circle;
  for (int i = 0; i <= 200; ++i) {
    const double a = 2.0 * M_PI * i / 200.0;
    circle.push_back({double(i), std::sin(a), 1.0 - std::cos(a), a});
  }
  const TaughtPath path(circle);
  EXPECT_NEAR(path.length(), 2.0 * M_PI, 1e-3);
  const PathLocation middle = path.Locate({0.0, 1.8, M_PI}, 0.0, path.length());  // inside, at the top
  EXPECT_NEAR(middle.s, M_PI, 1e-2);
  EXPECT_NEAR(middle.lateral, 0.2, 1e-3);  // the centre is left of a counter-clockwise circle
  EXPECT_NEAR(middle.curvature, 1.0, 1e-2);
  // Near the start, searched late in the route: the end of the loop, not its beginning.
  EXPECT_GT(path.Locate({0.0, 0.0, 0.0}, 5.0, path.length()).s, 5.0);
  EXPECT_LT(path.Locate({0.0, 0.0, 0.0}, 0.0, 1.0).s, 0.1);
}

// A unicycle at `speed` steered by PathFollowingTurnRate along a straight path, from an offset.
double LateralAfter(double distance, double start_lateral, double start_heading, double speed) {
  const TaughtPath path(StraightPath(20.0));
  cv::Vec3d pose(speed > 0 ? 1.0 : 19.0, start_lateral, start_heading);
  const double dt = 0.05;
  for (double driven = 0.0; driven < distance; driven += std::abs(speed) * dt) {
    const PathLocation at = path.Locate(pose, 0.0, path.length());
    const double w = PathFollowingTurnRate(at, speed, 0.6);
    pose[0] += speed * dt * std::cos(pose[2]);
    pose[1] += speed * dt * std::sin(pose[2]);
    pose[2] += w * dt;
  }
  return path.Locate(pose, 0.0, path.length()).lateral;
}

TEST(PathFollowing, AnOffsetDecaysWithinAFewConvergenceDistances) {
  EXPECT_LT(std::abs(LateralAfter(3.0, 0.5, 0.0, 0.3)), 0.02);
  EXPECT_LT(std::abs(LateralAfter(3.0, -0.4, 0.17, 0.3)), 0.02);
  // Driven backwards along the path (the teach heading kept), the offset decays too.
  EXPECT_LT(std::abs(LateralAfter(3.0, 0.3, 0.0, -0.3)), 0.02);
  // Not yet after a fraction of one.
  EXPECT_GT(std::abs(LateralAfter(0.2, 0.5, 0.0, 0.3)), 0.3);
}

TEST(PathFollowing, LeftOfThePathTurnsRightAndAFarOffsetIsCapped) {
  PathLocation left;
  left.lateral = 0.2;
  EXPECT_LT(PathFollowingTurnRate(left, 0.3, 0.6), 0.0);
  PathLocation far = left, farther = left;
  far.lateral = 0.6;
  farther.lateral = 3.0;
  EXPECT_DOUBLE_EQ(PathFollowingTurnRate(far, 0.3, 0.6), PathFollowingTurnRate(farther, 0.3, 0.6));
  PathLocation curve;
  curve.curvature = 0.5;
  EXPECT_DOUBLE_EQ(PathFollowingTurnRate(curve, 0.4, 0.6), 0.2);  // on the path: the taught turn
}

TEST(RoutePoseEstimator, BearingsToKnownLandmarksCorrectAnOffset) {
  // The robot drives along y = 0.3 while the estimate starts on y = 0, unsure by half a metre; landmarks
  // (where key images were taken) lie every metre along y = 0.
  RoutePoseEstimator estimator;
  cv::Vec3d truth(0.0, 0.3, 0.0);
  estimator.Initialize({0.0, 0.0, 0.0}, {0.5, 0.5, 0.05});
  for (int step = 0; step < 40; ++step) {
    truth[0] += 0.05;
    estimator.Predict(0.05, 0.0);
    const cv::Point2d landmark(std::floor(truth[0]) + 2.0, 0.0);
    const double bearing = std::atan2(landmark.y - truth[1], landmark.x - truth[0]) - truth[2];
    EXPECT_TRUE(estimator.UpdateBearing(landmark, bearing));
    EXPECT_TRUE(estimator.UpdateHeading(truth[2], 0.02));
  }
  EXPECT_NEAR(estimator.pose()[1], 0.3, 0.03);
  EXPECT_NEAR(estimator.pose()[0], truth[0], 0.1);
  // Once sure, a bearing far from what it predicts is an outlier: refused, and the estimate stays.
  const cv::Vec3d before = estimator.pose();
  EXPECT_FALSE(estimator.UpdateBearing({truth[0] + 2.0, 0.0}, 1.0));
  EXPECT_EQ(estimator.pose(), before);
}

// An estimate sure of a wrong heading (a bad first frame): every true heading then looks like an outlier.
// Without the recovery it refuses them all and stays wrong; with it, too many refusals widen its heading's
// uncertainty and the true headings, then the bearings, pull it back.
cv::Vec3d AfterWrongStart(RoutePoseEstimatorOptions options, int* recoveries) {
  RoutePoseEstimator estimator(options);
  cv::Vec3d truth(0.0, 0.2, 0.0);
  estimator.Initialize({0.0, 0.0, 0.4}, {0.1, 0.1, 0.02});
  for (int step = 0; step < 40; ++step) {
    truth[0] += 0.03;
    estimator.Predict(0.03, 0.0);
    const cv::Point2d landmark(std::floor(truth[0]) + 2.0, 0.0);
    estimator.UpdateHeading(truth[2], 0.02);
    estimator.UpdateBearing(landmark, std::atan2(landmark.y - truth[1], landmark.x - truth[0]) - truth[2]);
  }
  *recoveries = estimator.recoveries();
  return estimator.pose() - truth;
}

TEST(RoutePoseEstimator, RecoversFromAWrongHeadingItWasSureOf) {
  int recoveries = 0;
  RoutePoseEstimatorOptions never;  // the default
  const cv::Vec3d stuck = AfterWrongStart(never, &recoveries);
  EXPECT_GT(std::abs(stuck[2]), 0.3);
  EXPECT_EQ(recoveries, 0);
  RoutePoseEstimatorOptions recovering;
  recovering.recovery_window = 10;
  const cv::Vec3d error = AfterWrongStart(recovering, &recoveries);
  EXPECT_GE(recoveries, 1);
  EXPECT_LT(std::abs(error[2]), 0.03);
  EXPECT_LT(std::abs(error[1]), 0.05);
}

TEST(RoutePoseEstimator, ABearingCloseToTheKeyImageDoesNotThrowAnUnsureEstimateAlongItsLineOfSight) {
  // Unsure by 2 m along the route, sure across it; the key image 0.5 m ahead is seen 0.3 rad off what the
  // estimate predicts (a small error in a bearing this close). Linearized, the bearing would move the estimate
  // metres along its line of sight; the step limit refuses it.
  auto after = [](double share) {
    RoutePoseEstimatorOptions options;
    options.max_bearing_step_share = share;
    RoutePoseEstimator estimator(options);
    estimator.Initialize({0.5, 0.05, 0.0}, {2.0, 0.05, 0.01});
    estimator.UpdateBearing({1.0, 0.0}, -0.1 - 0.3);
    return estimator.pose();
  };
  EXPECT_GT(std::abs(after(1e9)[0] - 0.5), 1.0);
  EXPECT_NEAR(after(RoutePoseEstimatorOptions{}.max_bearing_step_share)[0], 0.5, 0.15);
  // Across the line of sight, what a bearing measures, a large correction is taken: 0.4 m off with the key image
  // 1 m ahead.
  RoutePoseEstimator estimator;
  estimator.Initialize({0.0, -0.2, 0.0}, {0.05, 0.5, 0.01});
  EXPECT_TRUE(estimator.UpdateBearing({1.0, 0.0}, std::atan2(-0.2, 1.0)));
  EXPECT_GT(estimator.pose()[1], 0.1);
}

// Key images 1 m apart along x, taken 10 s apart, on the teach path of StraightPath(4).
TaughtRoute StraightMetricRoute() {
  TaughtRoute route;
  route.keys = {0, 1, 2, 3};
  for (int k = 0; k < 4; ++k) route.key_poses.push_back({10.0 * k, 1.0 * k, 0.0, 0.0});
  for (int k = 0; k < 3; ++k) {
    TaughtSegment segment;
    segment.from_key = k;
    segment.to_key = k + 1;
    segment.duration = 10.0;
    segment.length = 1.0;
    segment.yaw_change = 0.0;
    route.segments.push_back(segment);
  }
  route.path = StraightPath(4.0);
  route.focal_px = 500.0;
  return route;
}

// A frame tracked between key images 1 and 2 whose pose to key image 2 has a rotation saying the robot points
// `rotation_offset` rad left of it, and whose features say `features_offset`.
LocalizationResult FrameWithHeadings(double rotation_offset, double features_offset) {
  LocalizationResult result;
  result.status = LocalizationStatus::kTracking;
  result.key = 1;
  result.next_key = 2;
  result.route_position = 1;
  result.progress = 0.5;
  result.heading_deg = features_offset * 180.0 / M_PI;
  const double a = -rotation_offset;  // YawOfCameraRotation of a turn about the camera's y axis by a
  result.to_next.pose.valid = true;
  result.to_next.pose.R = cv::Matx33d(std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a));
  result.to_next.pose.t = cv::Vec3d(0, 0, -1);
  return result;
}

TEST(RouteTracking, ARotationTheFeaturesContradictGivesNoHeading) {
  ASSERT_TRUE(StraightMetricRoute().metric());
  RouteTracking agreeing(StraightMetricRoute());
  agreeing.Observe(FrameWithHeadings(0.12, 0.1), 500.0);  // they agree: the rotation's, the surer
  EXPECT_NEAR(agreeing.pose()[2], 0.12, 1e-9);
  RouteTracking contradicted(StraightMetricRoute());
  contradicted.Observe(FrameWithHeadings(-0.35, 0.1), 500.0);  // a wrong rotation (or biased features): no heading
  EXPECT_FALSE(contradicted.started());
  RoutePoseEstimatorOptions trusting;
  trusting.rotation_agreement = M_PI;
  RouteTracking without(StraightMetricRoute(), trusting);
  without.Observe(FrameWithHeadings(-0.35, 0.1), 500.0);
  EXPECT_NEAR(without.pose()[2], -0.35, 1e-9);
}

TEST(RouteTracking, StartsAtTheKeyImageUnsureAlongTheRouteMoreThanAcrossIt) {
  RouteTracking tracking(StraightMetricRoute());
  EXPECT_FALSE(tracking.started());
  tracking.Observe(FrameWithHeadings(0.0, 0.0), 500.0);  // at key image 1, progress 0.5 towards 2
  ASSERT_TRUE(tracking.started());
  EXPECT_NEAR(tracking.pose()[0], 1.0, 1e-9);  // the key image's place, not the progress's
  EXPECT_NEAR(tracking.pose()[1], 0.0, 1e-9);
  EXPECT_NEAR(std::sqrt(tracking.covariance()(0, 0)), 1.0, 1e-9);   // one key image spacing along
  EXPECT_NEAR(std::sqrt(tracking.covariance()(1, 1)), 0.35, 1e-9);  // start_lateral_sigma across
}

// Another season: the frames verify a third of the matches the map's links do, and their poses' bearings are off
// by 0.1-0.45 rad either way (the simulator's michigan runs: a median error of 0.14-0.22 rad, against 0.01 rad in
// the teach run's appearance), their rotations by 0.03 rad. The robot drives 0.3 m left of the path. Returns the
// estimate's lateral error at the end.
double LateralErrorAcrossSeasons(RoutePoseEstimatorOptions options) {
  TaughtRoute route = StraightMetricRoute();
  for (TaughtSegment& segment : route.segments) segment.verified = 300;
  RouteTracking tracking(route, options);
  const double bearing_errors[] = {0.35, -0.3, 0.1, -0.15, 0.45, -0.4, 0.2, -0.25, 0.0, 0.3, -0.35, 0.15};
  const double heading_errors[] = {0.03, -0.03, 0.02, -0.02};
  cv::Vec2d truth(0.2, 0.3);
  for (int step = 0; step < 44; ++step) {
    if (step > 0) {
      truth[0] += 0.05;
      tracking.Predict(0.05, 0.0);
    }
    const int key = std::min(2, static_cast<int>(std::floor(truth[0])));
    const double heading = heading_errors[step % 4];
    LocalizationResult frame = FrameWithHeadings(heading, heading);
    frame.status = LocalizationStatus::kRelocalized;
    frame.key = key;
    frame.next_key = key + 1;
    frame.route_position = key;
    frame.to_next.num_verified = 100;
    // The pose's bearing to the next key image (at x = key + 1 on the path), wrong by the season's error: the key
    // image's centre in the camera's coordinates (x right, z forward) is -R^T t.
    const double bearing = std::atan2(-truth[1], key + 1.0 - truth[0]) + bearing_errors[step % 12];
    const cv::Vec3d centre(-std::sin(bearing), 0.0, std::cos(bearing));
    frame.to_next.pose.t = -(frame.to_next.pose.R * centre);
    frame.translation_known = true;
    tracking.Observe(frame, 500.0);
  }
  return tracking.pose()[1] - truth[1];
}

TEST(RouteTracking, AnotherSeasonsNoisyBearingsAreWeighedAsSuch) {
  EXPECT_NEAR(LateralErrorAcrossSeasons({}), 0.0, 0.1);
  RoutePoseEstimatorOptions as_the_teach_run;
  as_the_teach_run.weak_share = 0.0;  // every comparison measured as in the teach run's appearance
  EXPECT_GT(std::abs(LateralErrorAcrossSeasons(as_the_teach_run)), 0.15);
}

// Across seasons a first frame relocalized a key image ahead of the robot started the estimate there, and the
// bearings (which measure across their line of sight) never pulled it back. How large the key image's scene
// appears against its growth over the link into it says how far before or past the key image the robot is.
// Returns the estimate's error along the route after the robot drove 0.6 m from 0.2 m before key image 0... 1.
double AlongErrorAfterAWrongStart(RoutePoseEstimatorOptions options) {
  TaughtRoute route = StraightMetricRoute();
  for (TaughtSegment& segment : route.segments) segment.log_scale = std::log(0.8);  // 1 m: the scene grows 25 %
  const double depth = 4.0;  // of each key image's scene: 4 / (4 + 1) = 0.8
  RouteTracking tracking(route, options);
  double truth = 0.2;
  for (int step = 0; step < 13; ++step) {
    if (step > 0) {
      truth += 0.05;
      tracking.Predict(0.05, 0.0);
    }
    LocalizationResult frame = FrameWithHeadings(0.0, 0.0);
    frame.status = LocalizationStatus::kRelocalized;
    frame.key = step == 0 ? 1 : static_cast<int>(std::lround(truth));  // the first frame a key image ahead
    frame.next_key = frame.key + 1;
    frame.route_position = frame.key;
    frame.to_key.matched = true;
    frame.to_key.verified = testing::ZoomedMatches(depth / (depth - (truth - frame.key)));
    frame.to_key.num_verified = static_cast<int>(frame.to_key.verified.size());
    tracking.Observe(frame, 500.0);
  }
  return tracking.pose()[0] - truth;
}

TEST(RouteTracking, TheKeyImagesScaleTellsHowFarBeforeOrPastItTheRobotIs) {
  EXPECT_NEAR(AlongErrorAfterAWrongStart({}), 0.0, 0.1);
  RoutePoseEstimatorOptions bearings_only;
  bearings_only.scale_sigma = 0.0;
  EXPECT_GT(AlongErrorAfterAWrongStart(bearings_only), 0.6);  // still a key image ahead
}

// The scene of a key image 2 m ahead of it grows by 2 / (2 - d) when the robot is d metres past it (by 1.5 over the
// map's 1 m link into it): faster the nearer the robot. A robot stands `past` metres past key image 1, the estimate
// starts at the key image; returns where 20 frames of its scene put it, in metres past the key image. Taken as a
// straight line over the link (a rate per metre), the growth put the s-curve's robot 0.1-0.2 m farther past its
// first key image than it was, and the estimate entered the bend early.
double DistancePastAKeyImageFromItsScene(double past) {
  TaughtRoute route = StraightMetricRoute();
  const double depth = 2.0;
  for (TaughtSegment& segment : route.segments) segment.log_scale = std::log(depth / (depth + segment.length));
  RouteTracking tracking(route);
  for (int frame_index = 0; frame_index < 20; ++frame_index) {
    LocalizationResult frame = FrameWithHeadings(0.0, 0.0);
    frame.to_key.matched = true;
    frame.to_key.verified = testing::ZoomedMatches(depth / (depth - past));
    frame.to_key.num_verified = static_cast<int>(frame.to_key.verified.size());
    tracking.Observe(frame, 500.0);
  }
  return tracking.pose()[0] - route.key_poses[1].x;
}

TEST(RouteTracking, TheKeyImagesSceneGrowsFasterTheNearerTheRobotIs) {
  EXPECT_NEAR(DistancePastAKeyImageFromItsScene(-0.6), -0.6, 0.02);
  EXPECT_NEAR(DistancePastAKeyImageFromItsScene(0.25), 0.25, 0.02);
  // Farther past, the scene's nearest parts leave the view: not read (the estimate stays where it started).
  EXPECT_NEAR(DistancePastAKeyImageFromItsScene(0.6), 0.0, 1e-9);
}

// In the s-curve's bends the poses to the key image ahead (a wall seen obliquely) came with wrong rotations and
// bearings off by +0.13 to +0.30 rad together: a pose whose rotation the gate refuses gives no bearing.
TEST(RouteTracking, APoseWhoseRotationIsRefusedGivesNoBearing) {
  RouteTracking tracking(StraightMetricRoute());
  tracking.Observe(FrameWithHeadings(0.0, 0.0), 500.0);  // starts at key image 1, heading 0 within 0.04 rad
  ASSERT_TRUE(tracking.started());
  const auto with_bearing = [](double rotation_offset, double bearing) {
    LocalizationResult frame = FrameWithHeadings(rotation_offset, rotation_offset);
    const cv::Vec3d centre(-std::sin(bearing), 0.0, std::cos(bearing));  // key image 2 `bearing` rad left
    frame.to_next.pose.t = -(frame.to_next.pose.R * centre);
    frame.translation_known = true;
    return frame;
  };
  const TrackingObservation refused = tracking.Observe(with_bearing(0.3, 0.2), 500.0);
  EXPECT_EQ(refused.headings, 0);
  EXPECT_EQ(refused.bearings, 0);
  EXPECT_NEAR(tracking.pose()[1], 0.0, 1e-12);
  const TrackingObservation taken = tracking.Observe(with_bearing(0.0, 0.2), 500.0);  // the same with its heading
  EXPECT_EQ(taken.headings, 1);
  EXPECT_EQ(taken.bearings, 1);
  EXPECT_LT(tracking.pose()[1], -0.05);  // key image 2 seen left: the robot is right of the path
}

// A robot drives 18 m around a circle of radius 3 m (the simulator's loop) with the odometry 5 % too long; the
// key images, every metre of the circle, are seen ahead (a bearing every third frame) and the heading every frame.
// Returns the estimate's position error at the end; `scale` gets the estimated odometry scale.
double PositionErrorAroundACircle(RoutePoseEstimatorOptions options, double* scale) {
  constexpr double kRadius = 3.0, kStep = 0.03;
  RoutePoseEstimator estimator(options);
  cv::Vec3d truth(0.0, -kRadius, 0.0);  // on the circle about the origin, driving counter-clockwise
  estimator.Initialize(truth, {0.1, 0.1, 0.02});
  for (int step = 0; step < 600; ++step) {
    const double turn = kStep / kRadius;
    const double middle = truth[2] + 0.5 * turn;
    truth[0] += kStep * std::cos(middle);
    truth[1] += kStep * std::sin(middle);
    truth[2] += turn;
    estimator.Predict(kStep * 1.05, turn);
    estimator.UpdateHeading(truth[2], 0.02);
    if (step % 3 == 0) {
      // The next key image at least 0.5 m ahead along the circle.
      const double angle = std::ceil((truth[2] + 0.5 / kRadius) / (1.0 / kRadius)) * (1.0 / kRadius);
      const cv::Point2d landmark(kRadius * std::sin(angle), -kRadius * std::cos(angle));
      estimator.UpdateBearing(landmark, std::atan2(landmark.y - truth[1], landmark.x - truth[0]) - truth[2]);
    }
  }
  *scale = estimator.odometry_scale();
  return std::hypot(estimator.pose()[0] - truth[0], estimator.pose()[1] - truth[1]);
}

TEST(RoutePoseEstimator, LearnsTheOdometrysScaleErrorAndStaysWithTheRobot) {
  double scale = 0.0;
  RoutePoseEstimatorOptions fixed;
  fixed.odometry_scale_sigma = 0.0;  // the scale taken as 1: the estimate runs ahead
  const double fixed_error = PositionErrorAroundACircle(fixed, &scale);
  EXPECT_EQ(scale, 1.0);
  const double error = PositionErrorAroundACircle(RoutePoseEstimatorOptions{}, &scale);
  EXPECT_NEAR(scale, 1.0 / 1.05, 0.01);
  EXPECT_GT(fixed_error, 0.08);  // 0.12 m measured: about what the simulator's loop showed across the path
  EXPECT_LT(error, 0.2 * fixed_error);
}

TEST(RoutePoseEstimator, TheOdometrysScaleStaysWithinThreeStandardDeviations) {
  // Bearings that say the robot drives a third of what its odometry says (wrong ones, or a broken odometry):
  // the scale follows them only down to 1 - 3 sigma.
  RoutePoseEstimator estimator;
  cv::Vec3d truth(0.0, 0.0, 0.0);
  estimator.Initialize(truth, {0.05, 0.05, 0.01});
  const cv::Point2d landmark(5.0, 1.0);
  for (int step = 0; step < 100; ++step) {
    truth[0] += 0.01;
    estimator.Predict(0.03, 0.0);
    estimator.UpdateHeading(0.0, 0.02);
    estimator.UpdateBearing(landmark, std::atan2(landmark.y - truth[1], landmark.x - truth[0]));
  }
  const double sigma = RoutePoseEstimatorOptions{}.odometry_scale_sigma;
  EXPECT_NEAR(estimator.odometry_scale(), 1.0 - 3.0 * sigma, 1e-9);
}

TEST(RoutePoseEstimator, NothingIsMeasuredBeforeItStarts) {
  RoutePoseEstimator estimator;
  EXPECT_FALSE(estimator.initialized());
  EXPECT_FALSE(estimator.UpdateHeading(0.1, 0.02));
  EXPECT_FALSE(estimator.UpdateBearing({1.0, 0.0}, 0.0));
  estimator.Initialize({1.0, 2.0, 0.5}, {0.1, 0.1, 0.1});
  estimator.Predict(1.0, 0.0);
  EXPECT_NEAR(estimator.pose()[0], 1.0 + std::cos(0.5), 1e-12);
  EXPECT_NEAR(estimator.pose()[1], 2.0 + std::sin(0.5), 1e-12);
  EXPECT_FALSE(estimator.UpdateBearing({estimator.pose()[0], estimator.pose()[1]}, 0.0));  // under the robot
}

}  // namespace
}  // namespace vmap
