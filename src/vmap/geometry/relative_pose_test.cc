#include "vmap/geometry/relative_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"
#include "vmap/core/numeric.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/homography.h"
#include "vmap/geometry/pose_refinement.h"
#include "vmap/geometry/translation_evidence.h"
#include "vmap/testing/option_error.h"

namespace vmap {

namespace {

cv::Matx33d Rotation(const cv::Vec3d& axis_angle) {
  cv::Matx33d R;
  cv::Rodrigues(axis_angle, R);
  return R;
}

// Matches of random points seen by two cameras: X_to = R X_from + t (X_from in the first camera's frame).
struct Pair {
  std::vector<cv::Point2f> from, to;
};

Pair Observe(const Camera& camera, const cv::Matx33d& R, const cv::Vec3d& t, int count, double depth_min,
             double depth_max, double noise_px, double outlier_share, unsigned seed, bool planar = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), depth(depth_min, depth_max), u01(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  Pair pair;
  while (static_cast<int>(pair.from.size()) < count) {
    const double z = planar ? depth_min : depth(rng);
    const cv::Vec3d X(unit(rng) * 0.6 * z, unit(rng) * 0.45 * z, z);
    const cv::Vec3d Y = R * X + t;
    if (Y[2] <= 0.1) continue;
    cv::Point2f a(static_cast<float>(camera.fx * X[0] / X[2] + camera.cx + noise(rng)),
                  static_cast<float>(camera.fy * X[1] / X[2] + camera.cy + noise(rng)));
    cv::Point2f b(static_cast<float>(camera.fx * Y[0] / Y[2] + camera.cx + noise(rng)),
                  static_cast<float>(camera.fy * Y[1] / Y[2] + camera.cy + noise(rng)));
    if (u01(rng) < outlier_share) {
      b = cv::Point2f(static_cast<float>(camera.cx + unit(rng) * camera.cx),
                      static_cast<float>(camera.cy + unit(rng) * camera.cy));
    }
    pair.from.push_back(a);
    pair.to.push_back(b);
  }
  return pair;
}

const Camera& TestCamera() {
  static const Camera camera = Camera::Make(600, 600, 320, 240, {}, {640, 480});
  return camera;
}

}  // namespace

TEST(RelativePose, RecoversAKnownMotionWithNoiseAndOutliers) {
  const cv::Matx33d R = Rotation({0.02, -0.09, 0.01});
  const cv::Vec3d t = cv::normalize(cv::Vec3d(0.8, 0.05, -0.3));
  const Pair pair = Observe(TestCamera(), R, t * 0.4, 300, 2.0, 8.0, 0.5, 0.3, 1);
  for (bool all : {true, false}) {
    PoseOptions options;
    options.use_all_matches = all;
    const RelativePose pose = EstimateRelativePose(TestCamera(), pair.from, pair.to, options);
    ASSERT_TRUE(pose.valid);
    EXPECT_LT(RotationAngleDeg(pose.R.t() * R), 0.1);
    EXPECT_LT(AngleBetweenDeg(pose.t, t), 1.0);
    EXPECT_NEAR(cv::norm(pose.t), 1.0, 1e-9);
    EXPECT_GT(pose.num_inliers, 150);
  }
}

// The conventions, each checked so that the opposite one fails: X_to = R X_from + t, the first image is
// "from", and forward motion gives t = (0, 0, -1).
TEST(RelativePose, ConventionsForwardMotionAndImageOrder) {
  const cv::Matx33d R = Rotation({0.0, 0.05, 0.0});  // turning while driving forward
  // The "to" camera is 1 m ahead of "from" along from's optical axis: C_to = (0, 0, 1) in from's frame, so
  // X_to = R (X_from - C_to) and t = -R C_to.
  const cv::Vec3d C_to(0.0, 0.0, 1.0);
  const cv::Vec3d t = -(R * C_to);
  const Pair pair = Observe(TestCamera(), R, t, 200, 4.0, 30.0, 0.3, 0.0, 2);
  const RelativePose pose = EstimateRelativePose(TestCamera(), pair.from, pair.to, PoseOptions());
  ASSERT_TRUE(pose.valid);
  EXPECT_LT(AngleBetweenDeg(pose.t, cv::normalize(t)), 1.0);
  EXPECT_LT(pose.t[2], -0.99);  // forward motion: t points back, to where the first camera was
  EXPECT_LT(RotationAngleDeg(pose.R.t() * R), 0.1);
  // A point straight ahead of "from" is seen to the right in "to" (x grows): R, not its inverse.
  EXPECT_GT(pose.R(0, 2), 0.02);
  // Swapping the images gives the inverse motion: R^T and -R^T t.
  const RelativePose swapped = EstimateRelativePose(TestCamera(), pair.to, pair.from, PoseOptions());
  ASSERT_TRUE(swapped.valid);
  EXPECT_LT(RotationAngleDeg(swapped.R * pose.R), 0.1);
  EXPECT_LT(AngleBetweenDeg(swapped.t, -(pose.R.t() * pose.t)), 1.0);
  EXPECT_GT(AngleBetweenDeg(swapped.t, pose.t), 150.0);
}

TEST(RelativePose, FundamentalFromPoseAgreesWithProjectionsAndWithItsDecomposition) {
  const cv::Matx33d R = Rotation({0.03, 0.1, -0.02});
  const cv::Vec3d t = cv::normalize(cv::Vec3d(-0.5, 0.1, 0.4));
  const Pair pair = Observe(TestCamera(), R, t, 100, 2.0, 10.0, 0.0, 0.0, 3);
  const cv::Matx33d F = FundamentalFromPose(R, t, TestCamera().K());
  for (size_t i = 0; i < pair.from.size(); ++i) EXPECT_LT(SampsonDistance(F, pair.from[i], pair.to[i]), 1e-3);
  // The transposed F (the images' order swapped) does not fit.
  double swapped = 0;
  for (size_t i = 0; i < pair.from.size(); ++i) swapped += SampsonDistance(F.t(), pair.from[i], pair.to[i]);
  EXPECT_GT(swapped / pair.from.size(), 1.0);
  const RelativePose pose = PoseFromFundamental(F * 3.7, TestCamera(), pair.from, pair.to);
  ASSERT_TRUE(pose.valid);
  EXPECT_LT(RotationAngleDeg(pose.R.t() * R), 1e-3);
  EXPECT_LT(AngleBetweenDeg(pose.t, t), 1e-3);
}

// A hand-held camera moving 1 cm in front of a table 1.5 m away: every point is more than 50 baselines
// away, where cv::recoverPose's default gives up. The pose must still come out.
TEST(RelativePose, ShortBaselineStillGivesAPose) {
  const cv::Matx33d R = Rotation({0.004, -0.006, 0.002});
  const cv::Vec3d t = cv::normalize(cv::Vec3d(0.9, -0.2, 0.1));
  const Pair pair = Observe(TestCamera(), R, t * 0.01, 250, 1.2, 2.0, 0.2, 0.1, 4);
  const RelativePose pose = EstimateRelativePose(TestCamera(), pair.from, pair.to, PoseOptions());
  ASSERT_TRUE(pose.valid);
  EXPECT_LT(RotationAngleDeg(pose.R.t() * R), 0.2);
  EXPECT_LT(AngleBetweenDeg(pose.t, t), 15.0);
}

TEST(RelativePose, RefinementLowersTheCostOfAPerturbedPose) {
  const cv::Matx33d R = Rotation({0.01, 0.04, 0.0});
  const cv::Vec3d t = cv::normalize(cv::Vec3d(1.0, 0.0, -0.2));
  const Pair pair = Observe(TestCamera(), R, t * 0.5, 200, 2.0, 8.0, 0.5, 0.2, 5);
  RelativePose start;
  start.valid = true;
  start.R = R * Rotation({0.004, -0.003, 0.002});
  start.t = cv::normalize(t + cv::Vec3d(0.0, 0.05, 0.03));
  PoseOptions options;
  const RelativePose refined = RefineRelativePose(start, TestCamera(), pair.from, pair.to, 3.0, 1.0);
  EXPECT_LT(PoseCost(refined, TestCamera(), pair.from, pair.to, options),
            PoseCost(start, TestCamera(), pair.from, pair.to, options));
  EXPECT_LT(RotationAngleDeg(refined.R.t() * R), RotationAngleDeg(start.R.t() * R));
  EXPECT_LT(AngleBetweenDeg(refined.t, t), AngleBetweenDeg(start.t, t));
  EXPECT_NEAR(cv::norm(refined.t), 1.0, 1e-9);
}

TEST(RelativePose, SameInputSamePose) {
  const Pair pair = Observe(TestCamera(), Rotation({0.0, 0.05, 0.0}), {0.3, 0.0, -0.2}, 200, 2, 9, 0.5, 0.3, 6);
  const RelativePose a = EstimateRelativePose(TestCamera(), pair.from, pair.to, PoseOptions());
  const RelativePose b = EstimateRelativePose(TestCamera(), pair.from, pair.to, PoseOptions());
  ASSERT_TRUE(a.valid);
  EXPECT_EQ(a.R, b.R);
  EXPECT_EQ(a.t, b.t);
}

TEST(RelativePose, TooFewMatchesGiveNoPoseAndBadOptionsAreRefused) {
  const Pair pair = Observe(TestCamera(), Rotation({0, 0.05, 0}), {0.3, 0, 0}, 6, 2, 9, 0.0, 0.0, 7);
  EXPECT_FALSE(EstimateRelativePose(TestCamera(), pair.from, pair.to, PoseOptions()).valid);
  PoseOptions bad;
  bad.threshold = 0;
  EXPECT_EQ(testing::OptionErrorPath([&] { bad.Check(); }), "threshold");
  bad = PoseOptions();
  bad.starts = -1;
  EXPECT_EQ(testing::OptionErrorPath([&] { bad.Check(); }), "starts");
  EXPECT_EQ(ParsePoseMethod("fundamental"), PoseMethod::kFromFundamental);
  EXPECT_THROW(ParsePoseMethod("homography"), InputError);
}

TEST(RelativePose, DisplacementsRemoveTheRotationOnly) {
  // A pure rotation: large plain displacements, none once the rotation is undone.
  const cv::Matx33d R = Rotation({0.01, 0.06, 0.0});
  const Pair rotation = Observe(TestCamera(), R, {0, 0, 0}, 100, 2, 9, 0.0, 0.0, 8);
  const std::vector<double> plain = Displacements(rotation.from, rotation.to);
  const std::vector<double> without = Displacements(rotation.from, rotation.to, &TestCamera(), &R);
  EXPECT_GT(Median(plain), 30.0);
  EXPECT_LT(Median(without), 1e-3);
  // Undoing the inverse rotation doubles the displacement instead: the direction matters.
  const cv::Matx33d inverse = R.t();
  EXPECT_GT(Median(Displacements(rotation.from, rotation.to, &TestCamera(), &inverse)), 1.5 * Median(plain));
  // With a translation, parallax remains after the rotation is undone.
  const Pair moved = Observe(TestCamera(), R, {0.5, 0, 0}, 100, 2, 9, 0.0, 0.0, 9);
  EXPECT_GT(Median(Displacements(moved.from, moved.to, &TestCamera(), &R)), 20.0);
}

TEST(RelativePose, AnglesOfRotationsAndDirections) {
  EXPECT_NEAR(RotationAngleDeg(Rotation({0, 0, CV_PI / 2})), 90.0, 1e-9);
  EXPECT_NEAR(RotationAngleDeg(cv::Matx33d::eye()), 0.0, 1e-9);
  EXPECT_NEAR(AngleBetweenDeg({1, 0, 0}, {0, 2, 0}), 90.0, 1e-9);
  EXPECT_NEAR(AngleBetweenDeg({1, 0, 0}, {-3, 0, 0}), 180.0, 1e-9);
  EXPECT_NEAR(AngleBetweenDeg({1, 0, 0}, {1, 1e-7, 0}), 1e-7 * 180 / CV_PI, 1e-12);
}

TEST(Homography, ExplainsAPlaneAndAPureRotationButNotADeepSceneSeenFromAfar) {
  HomographyOptions options;
  const Pair plane = Observe(TestCamera(), Rotation({0, 0.03, 0}), {0.4, 0, 0}, 200, 3.0, 3.0, 0.3, 0.0, 10,
                             /*planar=*/true);
  EXPECT_TRUE(CheckHomography(plane.from, plane.to, options).explains);
  const Pair rotation = Observe(TestCamera(), Rotation({0.02, 0.05, 0}), {0, 0, 0}, 200, 1.0, 20.0, 0.3, 0.0, 11);
  EXPECT_TRUE(CheckHomography(rotation.from, rotation.to, options).explains);
  const Pair deep = Observe(TestCamera(), Rotation({0, 0.03, 0}), {0.4, 0, 0}, 200, 1.0, 20.0, 0.3, 0.0, 12);
  const HomographyCheck check = CheckHomography(deep.from, deep.to, options);
  EXPECT_TRUE(check.estimated);
  EXPECT_FALSE(check.explains);
  EXPECT_LT(check.share, 0.5);
  EXPECT_FALSE(CheckHomography({{0, 0}, {1, 1}}, {{0, 0}, {1, 1}}, options).estimated);
}

}  // namespace vmap

namespace vmap {

// Sampson errors are the same for t and -t, so a refinement started from the reversed pose ends at the same
// cost with t pointing backwards; the estimate must put the matches in front of both cameras again.
TEST(RelativePose, FinalPoseNeverPointsBackwardsWhenTheOptimumIsReachedFromTheReversedStart) {
  const cv::Matx33d R = Rotation({0.0, 0.03, 0.0});
  const cv::Vec3d t_true(0.0, 0.0, -1.0);  // driving forward
  const Pair pair = Observe(TestCamera(), R, t_true * 0.5, 200, 3.0, 20.0, 0.3, 0.0, 7);
  RelativePose reversed;
  reversed.valid = true;
  reversed.R = R;
  reversed.t = -t_true;
  reversed.num_inliers = 200;
  // The refinement alone reaches the Sampson optimum with the reversed t.
  const RelativePose refined = RefineRelativePose(reversed, TestCamera(), pair.from, pair.to, 3.0, 1.0);
  ASSERT_TRUE(refined.valid);
  ASSERT_GT(AngleBetweenDeg(refined.t, t_true), 170.0);
  PoseOptions options;
  options.starts = 0;  // only the reversed start
  const RelativePose pose = EstimateRelativePose(TestCamera(), pair.from, pair.to, options, {reversed});
  ASSERT_TRUE(pose.valid);
  EXPECT_LT(AngleBetweenDeg(pose.t, t_true), 2.0);
  EXPECT_LT(RotationAngleDeg(pose.R.t() * R), 0.2);
  EXPECT_NEAR(PoseCost(pose, TestCamera(), pair.from, pair.to, options),
              PoseCost(refined, TestCamera(), pair.from, pair.to, options), 1e-6);
  // And so does the decision on its own, for each of the four poses the optimum's E allows.
  for (const double sign : {1.0, -1.0}) {
    RelativePose start = refined;
    start.t = sign * refined.t;
    const RelativePose decided = EnforceCheirality(start, TestCamera(), pair.from, pair.to, 1.0);
    EXPECT_LT(AngleBetweenDeg(decided.t, t_true), 2.0);
  }
}

// The translation's direction is well determined by matches spread over the image and not by the same motion
// seen through a small patch, where a sideways translation and a rotation look alike. (At a vanishing baseline
// the linearised covariance is not to be trusted: the noise itself gives the cost a slope along t. That case
// is TranslationKnown's parallax test.)
TEST(RelativePose, TranslationSigmaIsLargeWhereRotationAndTranslationLookAlike) {
  const cv::Matx33d R = Rotation({0.01, 0.04, 0.0});
  const cv::Vec3d t = cv::normalize(cv::Vec3d(1.0, 0.0, -0.3));
  const Pair all = Observe(TestCamera(), R, t * 0.3, 3000, 3.0, 20.0, 0.5, 0.0, 3);
  Pair spread, patch;
  for (size_t i = 0; i < all.from.size(); ++i) {
    const bool central = cv::norm(all.from[i] - cv::Point2f(320, 240)) < 40.0;
    if (central) {
      patch.from.push_back(all.from[i]);
      patch.to.push_back(all.to[i]);
    } else if (spread.from.size() < 300) {
      spread.from.push_back(all.from[i]);
      spread.to.push_back(all.to[i]);
    }
  }
  ASSERT_GE(patch.from.size(), 12u);
  RelativePose pose;
  pose.valid = true;
  pose.R = R;
  pose.t = t;
  const double spread_sigma = TranslationSigmaDeg(pose, TestCamera(), spread.from, spread.to, 3.0, 1.0);
  const double patch_sigma = TranslationSigmaDeg(pose, TestCamera(), patch.from, patch.to, 3.0, 1.0);
  EXPECT_LT(spread_sigma, 2.0);
  EXPECT_GT(patch_sigma, 5.0 * spread_sigma);
  EXPECT_EQ(TranslationSigmaDeg(pose, TestCamera(), {patch.from.begin(), patch.from.begin() + 6},
                                {patch.to.begin(), patch.to.begin() + 6}, 3.0, 1.0),
            180.0)
      << "too few matches";
  TranslationOptions options;
  options.max_sigma_deg = 0.0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "max_sigma_deg");
  options = TranslationOptions();
  options.min_parallax_px = -1.0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "min_parallax_px");
  EXPECT_TRUE(TranslationKnown(1.0, 10.0, TranslationOptions()));
  EXPECT_FALSE(TranslationKnown(1.0, 1.0, TranslationOptions())) << "too little parallax";
  EXPECT_FALSE(TranslationKnown(30.0, 10.0, TranslationOptions())) << "too uncertain";
  EXPECT_FALSE(TranslationKnown(-1.0, 10.0, TranslationOptions())) << "not computed";
}

// A pose's flags: a sideways step seen over the whole image is known; the same step seen from ten times as far
// (little parallax left once the rotation is undone) is not, nor is a pose with a rival almost as cheap.
TEST(RelativePose, AssessTranslationTrustsADirectionOnlyWithParallaxSigmaAndNoRival) {
  const cv::Matx33d R = Rotation({0.01, 0.05, 0.0});
  const cv::Vec3d t = cv::normalize(cv::Vec3d(1.0, 0.0, -0.2));
  RelativePose pose;
  pose.valid = true;
  pose.R = R;
  pose.t = t;
  const Pair near = Observe(TestCamera(), R, t * 0.5, 300, 2.0, 8.0, 0.3, 0.0, 5);
  const NormalizedMatches near_matches(TestCamera(), near.from, near.to);
  const TranslationEvidence known =
      AssessTranslation(pose, near_matches, near_matches, PoseOptions(), TranslationOptions());
  EXPECT_TRUE(known.known);
  EXPECT_LT(known.sigma_deg, TranslationOptions().max_sigma_deg);
  EXPECT_GT(known.parallax_px, 20.0);
  EXPECT_DOUBLE_EQ(known.parallax_px, Median(Displacements(near.from, near.to, &TestCamera(), &R)));

  const Pair far = Observe(TestCamera(), R, t * 0.5, 300, 200.0, 800.0, 0.3, 0.0, 5);
  const NormalizedMatches far_matches(TestCamera(), far.from, far.to);
  const TranslationEvidence distant =
      AssessTranslation(pose, far_matches, far_matches, PoseOptions(), TranslationOptions());
  EXPECT_LT(distant.parallax_px, TranslationOptions().min_parallax_px);
  EXPECT_FALSE(distant.known);

  EXPECT_FALSE(AssessTranslation(pose, near_matches, near_matches, PoseOptions(), TranslationOptions(), 1.0).known)
      << "a rival 1 cost unit away";
}

}  // namespace vmap

namespace vmap {

TEST(RelativePose, RivalCostGapIsTheCheapestMinimumWhoseTranslationPointsElsewhere) {
  const auto minimum = [](const cv::Vec3d& t, double cost) {
    PoseMinimum m;
    m.pose.valid = true;
    m.pose.t = cv::normalize(t);
    m.cost = cost;
    return m;
  };
  const cv::Vec3d forward(0, 0, 1);
  const cv::Vec3d near_forward = Rotation({0.0, 5.0 * CV_PI / 180, 0.0}) * forward;
  const cv::Vec3d sideways = Rotation({0.0, 30.0 * CV_PI / 180, 0.0}) * forward;
  EXPECT_TRUE(std::isinf(RivalCostGap({}, 15.0)));
  EXPECT_TRUE(std::isinf(RivalCostGap({minimum(forward, 10.0), minimum(near_forward, 10.5)}, 15.0)))
      << "5 degrees away is the same valley";
  // The cheapest is the chosen pose, wherever it is in the list; the rival is the cheapest of the others
  // more than 15 degrees away.
  EXPECT_DOUBLE_EQ(RivalCostGap({minimum(sideways, 19.0), minimum(near_forward, 10.5), minimum(forward, 10.0),
                                 minimum(-forward, 13.0)},
                                15.0),
                   3.0);
  EXPECT_DOUBLE_EQ(RivalCostGap({minimum(sideways, 19.0), minimum(forward, 10.0)}, 40.0),
                   std::numeric_limits<double>::infinity());

  TranslationOptions options;
  EXPECT_TRUE(TranslationKnown(1.0, 10.0, 20.0, options));
  EXPECT_FALSE(TranslationKnown(1.0, 10.0, 3.0, options)) << "a rival almost as cheap";
  EXPECT_TRUE(TranslationKnown(1.0, 10.0, options)) << "no rival";
  options.min_rival_cost_gap = 0.0;
  EXPECT_TRUE(TranslationKnown(1.0, 10.0, 0.0, options)) << "0: never ambiguous";
  options.min_rival_cost_gap = -1.0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "min_rival_cost_gap");
  options = TranslationOptions();
  options.rival_angle_deg = 180.0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "rival_angle_deg");
}

namespace {

// The rival gap of a pair's pose as a map's link gets it (mapping/link_analysis.cc): EstimateRelativePose's
// minima and ProbeTranslation's at twice the rival angle, the cheapest of them the pose; default options.
double EstimatedRivalGap(const Pair& pair, RelativePose* pose) {
  const PoseOptions options;
  const double rival_angle = TranslationOptions().rival_angle_deg;
  std::vector<PoseMinimum> minima;
  const RelativePose estimate = EstimateRelativePose(TestCamera(), pair.from, pair.to, options, {}, &minima);
  if (!estimate.valid) return -1.0;
  const std::vector<PoseMinimum> probes =
      ProbeTranslation(estimate, TestCamera(), pair.from, pair.to, options, 2.0 * rival_angle);
  minima.insert(minima.end(), probes.begin(), probes.end());
  *pose = std::min_element(minima.begin(), minima.end(), [](const PoseMinimum& a, const PoseMinimum& b) {
            return a.cost < b.cost;
          })->pose;
  return RivalCostGap(minima, rival_angle);
}

}  // namespace

// Forward motion through a deep scene: every start ends in the valley of the true translation.
TEST(RelativePose, ForwardMotionHasNoRivalMinimum) {
  const cv::Matx33d R = Rotation({0.0, 0.03, 0.0});
  const cv::Vec3d t_true(0.0, 0.0, -1.0);
  const Pair pair = Observe(TestCamera(), R, t_true * 0.5, 300, 3.0, 30.0, 0.5, 0.2, 11);
  RelativePose pose;
  const double gap = EstimatedRivalGap(pair, &pose);
  ASSERT_TRUE(pose.valid);
  EXPECT_LT(AngleBetweenDeg(pose.t, t_true), 3.0);
  EXPECT_GE(gap, TranslationOptions().min_rival_cost_gap);
}

// A pure rotation leaves the translation free: probes started away from the pose's t stay there at its cost.
TEST(RelativePose, PureRotationHasARivalAsCheapAsThePose) {
  const Pair pair =
      Observe(TestCamera(), Rotation({0.02, 0.08, 0.01}), cv::Vec3d(0, 0, 0), 300, 3.0, 30.0, 0.5, 0.2, 13);
  RelativePose pose;
  const double gap = EstimatedRivalGap(pair, &pose);
  ASSERT_TRUE(pose.valid);
  EXPECT_LT(gap, TranslationOptions().min_rival_cost_gap);
}

// A plane seen from a short sideways baseline (1 cm at 2 m): one homography explains every match, and with
// so little parallax a pose can trade translation for rotation almost freely; the probes find such a pose.
// (The plane's second discrete pose, far from the first, is found only where a start falls near it.)
TEST(RelativePose, PlanarSceneHasARivalMinimum) {
  const cv::Vec3d t_true = cv::normalize(cv::Vec3d(1.0, 0.0, -0.2));
  const Pair pair = Observe(TestCamera(), Rotation({0.0, 0.02, 0.0}), t_true * 0.01, 300, 2.0, 2.0, 0.5, 0.2, 17,
                            /*planar=*/true);
  RelativePose pose;
  const double gap = EstimatedRivalGap(pair, &pose);
  ASSERT_TRUE(pose.valid);
  EXPECT_LT(gap, TranslationOptions().min_rival_cost_gap);
}

// Small angles are where link rotation errors live; the cosine alone read 1e-6 degrees as 1.2e-6, and this
// identity rounded below 1 as 0.05 degrees.
TEST(RelativePose, RotationAngleIsAccurateFromZeroToAHalfTurn) {
  for (const double degrees : {1e-6, 1e-4, 0.01, 1.0, 45.0, 90.0, 179.0, 180.0}) {
    cv::Matx33d R;
    cv::Rodrigues(cv::normalize(cv::Vec3d(0.3, -1.0, 0.2)) * (degrees * CV_PI / 180.0), R);
    EXPECT_NEAR(RotationAngleDeg(R), degrees, degrees * 1e-6 + 1e-9) << degrees;
  }
  // A symmetric error, as rounding a matrix's entries leaves, is no rotation.
  const cv::Matx33d rounded(1.0 - 3e-7, 2e-7, -1e-7, 2e-7, 1.0 - 4e-7, 5e-8, -1e-7, 5e-8, 1.0 - 1e-7);
  EXPECT_LT(RotationAngleDeg(rounded), 1e-9);
}

}  // namespace vmap
