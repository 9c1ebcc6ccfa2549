#include "vmap/control/guidance_signals.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

namespace vmap {
namespace {

// The pose of a key image seen from a frame (X_key = R X_frame + t) for a key camera at `centre` (frame
// coordinates: x right, z forward) turned left by `yaw`.
RelativePose PoseOfKeyAt(cv::Vec3d centre, double yaw) {
  cv::Matx33d R_fk;  // the key camera's axes in the frame's coordinates
  cv::Rodrigues(cv::Vec3d(0, -yaw, 0), R_fk);
  RelativePose pose;
  pose.valid = true;
  pose.R = R_fk.t();
  const cv::Vec3d t = -(pose.R * centre);
  pose.t = t / cv::norm(t);
  return pose;
}

TEST(GuidanceSignals, BearingToAKeyImageAheadOnTheLeft) {
  // The key image 2 m ahead and 0.5 m to the left, looking straight ahead: it is on the left (alpha > 0), and
  // the robot is right of the key image's line (beta < 0).
  const TargetBearing b = BearingToKey(PoseOfKeyAt({-0.5, 0, 2.0}, 0.0));
  ASSERT_TRUE(b.valid);
  EXPECT_NEAR(b.bearing, std::atan2(0.5, 2.0), 1e-9);
  EXPECT_NEAR(b.key_heading, 0.0, 1e-9);
  EXPECT_LT(b.line_angle(), 0.0);
  // Looking 0.2 rad left of the robot, straight ahead of it: only the heading differs.
  const TargetBearing turned = BearingToKey(PoseOfKeyAt({0, 0, 2.0}, 0.2));
  ASSERT_TRUE(turned.valid);
  EXPECT_NEAR(turned.bearing, 0.0, 1e-9);
  EXPECT_NEAR(turned.key_heading, 0.2, 1e-9);
  // Behind the camera: no bearing to steer by.
  EXPECT_FALSE(BearingToKey(PoseOfKeyAt({0.3, 0, -1.0}, 0.0)).valid);
  EXPECT_FALSE(BearingToKey(RelativePose{}).valid);
}

TEST(GuidanceSignals, HeadingOffsetIsPositiveWhenTheRobotPointsLeft) {
  LocalizationResult result;
  result.heading_px = 40.0;  // the scene appears right of where the key image has it
  EXPECT_NEAR(HeadingOffset(result, 400.0), std::atan(0.1), 1e-12);
  EXPECT_TRUE(std::isnan(HeadingOffset(result, std::nan(""))));
  result.heading_deg = -3.0;  // degrees win where the camera gives them
  EXPECT_NEAR(HeadingOffset(result, 400.0), -3.0 * M_PI / 180.0, 1e-12);
}

TEST(GuidanceSignals, ApparentScaleOfAZoom) {
  // Points of the key image seen 10 % larger (about the image centre) in the frame: log(1.1).
  std::vector<Correspondence> matches;
  cv::RNG rng(3);
  for (int i = 0; i < 80; ++i) {
    const cv::Point2f key(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f));
    const cv::Point2f frame = cv::Point2f(320, 240) + 1.1f * (key - cv::Point2f(320, 240)) + cv::Point2f(15, -4);
    matches.push_back({frame, key});
  }
  EXPECT_NEAR(ApparentLogScale(matches), std::log(1.1), 1e-5);
  for (Correspondence& m : matches) std::swap(m.p0, m.p1);
  EXPECT_NEAR(ApparentLogScale(matches), -std::log(1.1), 1e-5);
  matches.resize(3);
  EXPECT_TRUE(std::isnan(ApparentLogScale(matches)));  // too few pairs
}

// The matches of points on a wall ahead, turned 40 degrees from the optical axis (a corridor's outer wall in a
// bend), seen by the key image's camera at the origin and by a frame's camera at `centre` turned left by `yaw`
// (pinhole 457 px, 640 x 480; x right, y down, z forward).
std::vector<Correspondence> ObliqueWallMatches(cv::Vec3d centre, double yaw = 0.0) {
  const auto project = [](cv::Vec3d point) {
    return cv::Point2f(static_cast<float>(320.0 + 457.0 * point[0] / point[2]),
                       static_cast<float>(240.0 + 457.0 * point[1] / point[2]));
  };
  // The frame's axes in the key camera's: x (cos, 0, sin), z (-sin, 0, cos).
  const auto in_frame = [&](cv::Vec3d point) {
    const cv::Vec3d d = point - centre;
    return cv::Vec3d(d[0] * std::cos(yaw) + d[2] * std::sin(yaw), d[1], -d[0] * std::sin(yaw) + d[2] * std::cos(yaw));
  };
  const double angle = 40.0 * M_PI / 180.0;
  std::vector<Correspondence> matches;
  cv::RNG rng(5);
  for (int i = 0; i < 150; ++i) {
    const double along = rng.uniform(-3.0, 3.0);
    const cv::Vec3d point(along * std::sin(angle), rng.uniform(-1.5, 0.5), 4.0 + along * std::cos(angle));
    const cv::Point2f key = project(point), frame = project(in_frame(point));
    if (key.x < 0 || key.x > 640 || frame.x < 0 || frame.x > 640 || key.y > 480 || frame.y > 480) continue;
    matches.push_back({frame, key});
  }
  return matches;
}

TEST(GuidanceSignals, ASideStepChangesNoApparentScaleABackStepDoes) {
  // A step sideways leaves every point's depth, so how near the scene is, as it was; but the oblique wall is
  // seen more or less head-on, so its horizontal extent changes (by 7 % here): measured on whole distances, a
  // robot 0.3 m beside the path looked 0.3 m behind (in the simulator's s-curve, a robot starting left of the
  // path looked a metre ahead of where it was, and turned into the bend early). Vertical distances scale with
  // the depth alone.
  EXPECT_NEAR(ApparentLogScale(ObliqueWallMatches({-0.3, 0, 0})), 0.0, 0.005);
  EXPECT_NEAR(ApparentLogScale(ObliqueWallMatches({0.3, 0, 0})), 0.0, 0.005);
  // 0.3 m back: the wall, about 4 m ahead, appears about 7 % smaller.
  EXPECT_LT(ApparentLogScale(ObliqueWallMatches({0, 0, -0.3})), -0.05);
}

TEST(GuidanceSignals, AFrameTurnedIsSeenWithTheKeyImagesHeadingBeforeItsScaleIsRead) {
  // Turned 0.2 rad left at the key image's place, matches on the image's right side only (where the scene has
  // its features on a turn): they move out to the image's edge, where the scene looks larger, and the scale
  // reads a step forward (0.07 here, a quarter of a metre on the s-curve's links); with the turn undone, none.
  std::vector<Correspondence> turned;
  for (const Correspondence& match : ObliqueWallMatches({0, 0, 0}, 0.2)) {
    if (match.p1.x > 400.0f) turned.push_back(match);
  }
  ASSERT_GE(turned.size(), 30u);
  EXPECT_GT(ApparentLogScale(turned), 0.04);
  EXPECT_NEAR(ApparentLogScale(UndoFrameYaw(turned, 0.2, 457.0, {320.0, 240.0})), 0.0, 0.002);
  // Undone, every frame point is where the key image has it.
  const std::vector<Correspondence> undone =
      UndoFrameYaw(ObliqueWallMatches({0, 0, 0}, -0.3), -0.3, 457.0, {320.0, 240.0});
  for (const Correspondence& match : undone) EXPECT_LT(cv::norm(match.p0 - match.p1), 1e-3);
}

}  // namespace
}  // namespace vmap
