#include "vmap/control/taught_route.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"

namespace vmap {
namespace {

// A camera turning left by `yaw` (counter-clockwise seen from above) about its vertical (y, pointing down) axis.
cv::Matx33d CameraTurningLeft(double yaw) {
  // Turning left rotates the camera about -y; points then move right in its image (X_to = R X_from).
  cv::Matx33d R_wc;
  cv::Rodrigues(cv::Vec3d(0, -yaw, 0), R_wc);  // the new camera's axes in the old camera's frame
  return R_wc.t();
}

// Key images 0..3 taken 2 s apart; link 1 turns left by 0.3 rad.
VisualMap TurningMap() {
  VisualMap map;
  for (int k = 0; k < 4; ++k) {
    KeyImage key;
    key.timestamp = 10.0 + 2.0 * k;
    map.key_images.push_back(key);
  }
  for (int k = 0; k < 3; ++k) {
    Link link;
    link.from_key = k;
    link.to_key = k + 1;
    link.has_pose = true;
    link.R = CameraTurningLeft(k == 1 ? 0.3 : 0.0);
    map.links.push_back(link);
  }
  return map;
}

TEST(TaughtRoute, YawOfALeftTurnIsPositive) {
  EXPECT_NEAR(YawOfCameraRotation(CameraTurningLeft(0.3)), 0.3, 1e-12);
  EXPECT_NEAR(YawOfCameraRotation(CameraTurningLeft(-0.2)), -0.2, 1e-12);
}

TEST(TaughtRoute, DurationsFromTimestampsAndTurnsFromLinkPoses) {
  const TaughtRoute route = MakeTaughtRoute(TurningMap());
  EXPECT_EQ(route.keys, (std::vector<int>{0, 1, 2, 3}));
  ASSERT_EQ(route.segments.size(), 3u);
  EXPECT_DOUBLE_EQ(route.segments[1].duration, 2.0);
  EXPECT_NEAR(route.segments[1].yaw_change, 0.3, 1e-12);
  EXPECT_NEAR(route.segments[0].yaw_change, 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(route.segments[1].length));  // no odometry
  EXPECT_TRUE(std::isnan(route.segments[1].speed()));
  EXPECT_TRUE(std::isnan(route.focal_px));  // no camera
  EXPECT_EQ(route.goal(), 3);
  EXPECT_EQ(route.PositionOf(2), 2);
  EXPECT_EQ(route.PositionOf(7), -1);
}

TEST(TaughtRoute, TheLinksMatchesTellHowMuchTheNextScenesGrows) {
  VisualMap map = TurningMap();
  // Link 2 (key images 2 -> 3): key image 3 sees key image 2's points 10 % larger; 60 verified, then 5 rejected
  // matches that say otherwise.
  Link& link = map.links[2];
  for (int i = 0; i < 65; ++i) {
    const cv::Point2f at2(40.f + 9.f * i, 60.f + static_cast<float>((i * 37) % 360));
    const cv::Point2f at3 = i < 60 ? cv::Point2f(320, 240) + 1.1f * (at2 - cv::Point2f(320, 240)) : at2 * 3.f;
    link.correspondences.push_back({at2, at3});
  }
  link.num_verified = 60;
  const TaughtRoute route = MakeTaughtRoute(map);
  EXPECT_NEAR(route.segments[2].log_scale, std::log(1.0 / 1.1), 1e-4);
  EXPECT_TRUE(std::isnan(route.segments[0].log_scale));  // no matches
  // Backwards (3 -> 2) the scene shrinks: the link is read the other way round.
  const TaughtRoute back = MakeTaughtRoute(map, {3, 2});
  EXPECT_NEAR(back.segments[0].log_scale, std::log(1.1), 1e-4);
}

TEST(TaughtRoute, BackwardsTheTurnIsUndone) {
  const TaughtRoute route = MakeTaughtRoute(TurningMap(), {3, 2, 1});
  ASSERT_EQ(route.segments.size(), 2u);
  EXPECT_TRUE(route.segments[1].backwards);
  EXPECT_NEAR(route.segments[1].yaw_change, -0.3, 1e-12);
  EXPECT_DOUBLE_EQ(route.segments[1].duration, 2.0);
}

TEST(TaughtRoute, OdometryGivesLengthsTurnsAndSpeeds) {
  // An arc of radius 2 m driven at 0.5 m/s from t = 10 to 16, left-turning (0.25 rad/s), sampled at 10 Hz.
  std::vector<OdometrySample> odometry;
  for (int i = 0; i <= 60; ++i) {
    const double t = 10.0 + 0.1 * i, yaw = 0.25 * (t - 10.0);
    odometry.push_back({t, 2.0 * std::sin(yaw), 2.0 * (1.0 - std::cos(yaw)), yaw});
  }
  const TaughtRoute route = MakeTaughtRoute(TurningMap(), {}, odometry);
  for (const TaughtSegment& segment : route.segments) {
    EXPECT_NEAR(segment.length, 1.0, 1e-3);  // 2 s at 0.5 m/s (the chords of 0.1 s add up to the arc)
    EXPECT_NEAR(segment.yaw_change, 0.5, 1e-9);
    EXPECT_NEAR(segment.speed(), 0.5, 1e-3);
  }
  // Metric: each key image's pose on the odometry, and the path driven from the first to the last.
  ASSERT_TRUE(route.metric());
  ASSERT_EQ(route.key_poses.size(), 4u);
  EXPECT_NEAR(route.key_poses[2].yaw, 1.0, 1e-9);
  EXPECT_NEAR(route.key_poses[2].x, 2.0 * std::sin(1.0), 1e-9);
  EXPECT_DOUBLE_EQ(route.path.front().timestamp, 10.0);
  EXPECT_DOUBLE_EQ(route.path.back().timestamp, 16.0);
  // Backwards, the path is listed in the order driven.
  const TaughtRoute back = MakeTaughtRoute(TurningMap(), {3, 2, 1}, odometry);
  ASSERT_TRUE(back.metric());
  EXPECT_DOUBLE_EQ(back.path.front().timestamp, 16.0);
  EXPECT_DOUBLE_EQ(back.path.back().timestamp, 12.0);
  // Without odometry, or with odometry that does not cover the route, it is not.
  EXPECT_FALSE(MakeTaughtRoute(TurningMap()).metric());
  odometry.resize(30);  // up to t = 12.9
  EXPECT_FALSE(MakeTaughtRoute(TurningMap(), {}, odometry).metric());
}

TEST(TaughtRoute, KeyImagesNoLinkJoinsAreRefused) {
  EXPECT_THROW(MakeTaughtRoute(TurningMap(), {0, 2}), InputError);
  EXPECT_THROW(MakeTaughtRoute(TurningMap(), {0, 9}), InputError);
}

TEST(Odometry, InterpolatesAlongTheShorterArc) {
  const std::vector<OdometrySample> samples = {{0.0, 0.0, 0.0, M_PI - 0.1}, {1.0, 1.0, 2.0, -M_PI + 0.1}};
  const auto middle = InterpolateOdometry(samples, 0.5);
  ASSERT_TRUE(middle);
  EXPECT_NEAR(middle->x, 0.5, 1e-12);
  EXPECT_NEAR(middle->y, 1.0, 1e-12);
  EXPECT_NEAR(std::abs(middle->yaw), M_PI, 1e-12);
  EXPECT_FALSE(InterpolateOdometry(samples, 1.5));
  EXPECT_FALSE(InterpolateOdometry({}, 0.0));
  EXPECT_NEAR(WrapAngle(3 * M_PI), M_PI, 1e-12);
}

}  // namespace
}  // namespace vmap
