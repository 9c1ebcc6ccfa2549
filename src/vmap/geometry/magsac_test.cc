#include "vmap/geometry/magsac.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/sources/frame_source.h"
#include "vmap/testing/shared_data.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

// Two views of a 3-D scene with known relative motion: `inliers` true correspondences with Gaussian noise of
// `noise` px, the first `on_plane` of them on one plane, then `outliers` random pairs.
struct Scene {
  std::vector<cv::Point2f> p0, p1;
  std::vector<cv::Point2f> exact0, exact1;  // the inliers without noise
  cv::Matx33d F_true;
  int inliers = 0;
};

Scene MakeScene(int inliers, int outliers, double noise, unsigned seed, int on_plane = 0) {
  Scene scene;
  cv::RNG rng(seed);
  const cv::Matx33d K(500, 0, 320, 0, 500, 240, 0, 0, 1);
  testing::CameraPose a, b;
  const double yaw = 0.05;
  b.R = cv::Matx33d(std::cos(yaw), 0, std::sin(yaw), 0, 1, 0, -std::sin(yaw), 0, std::cos(yaw));
  b.t = cv::Vec3d(-0.3, 0.02, -0.1);
  scene.F_true = testing::TrueFundamental(K, a, b);
  scene.inliers = inliers;
  for (int i = 0; i < inliers; ++i) {
    cv::Vec3d X(rng.uniform(-3.0, 3.0), rng.uniform(-2.0, 2.0), rng.uniform(4.0, 12.0));
    if (i < on_plane) X[2] = 7.0 + 0.3 * X[0] - 0.2 * X[1];  // a tilted plane in front of both cameras
    const cv::Vec3d x0 = K * X, x1 = K * (b.R * X + b.t);
    scene.exact0.emplace_back(x0[0] / x0[2], x0[1] / x0[2]);
    scene.exact1.emplace_back(x1[0] / x1[2], x1[1] / x1[2]);
    scene.p0.push_back(scene.exact0.back() + cv::Point2f(rng.gaussian(noise), rng.gaussian(noise)));
    scene.p1.push_back(scene.exact1.back() + cv::Point2f(rng.gaussian(noise), rng.gaussian(noise)));
  }
  for (int i = 0; i < outliers; ++i) {
    scene.p0.emplace_back(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f));
    scene.p1.emplace_back(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f));
  }
  return scene;
}

// Distance between two fundamental matrices up to scale and sign.
double ModelDistance(const cv::Matx33d& a, const cv::Matx33d& b) {
  const cv::Matx33d na = a * (1.0 / cv::norm(a)), nb = b * (1.0 / cv::norm(b));
  return std::min(cv::norm(na - nb), cv::norm(na + nb));
}

struct Kept {
  int inliers = 0, outliers = 0;
};
Kept Count(const Scene& scene, const FundamentalResult& result) {
  Kept kept;
  for (size_t i = 0; i < result.inlier_mask.size(); ++i) {
    if (result.inlier_mask[i]) (static_cast<int>(i) < scene.inliers ? kept.inliers : kept.outliers)++;
  }
  return kept;
}

double MeanTrueError(const Scene& scene, const cv::Matx33d& F, int first, int last) {
  double sum = 0;
  for (int i = first; i < last; ++i) sum += SampsonDistance(F, scene.exact0[i], scene.exact1[i]);
  return sum / (last - first);
}

TEST(Magsac, NoiseFreeCorrespondencesGiveTheTrueModel) {
  const Scene scene = MakeScene(100, 0, 0.0, 1);
  const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, scene.p1, {});
  ASSERT_TRUE(result.success);
  EXPECT_EQ(result.num_inliers, 100);
  EXPECT_LT(ModelDistance(result.F, scene.F_true), 1e-5);
}

class MagsacOutliers : public ::testing::TestWithParam<int> {};

// 200 true correspondences with 0.2 px noise and a growing share of outliers: the true ones are kept (a point
// with that noise is within 0.5 px of its epipolar line ~9 times in 10), the outliers are not, and F agrees
// with the true geometry on exact projections of the scene.
TEST_P(MagsacOutliers, RecoversTheGeometry) {
  const int outliers = GetParam();
  const Scene scene = MakeScene(200, outliers, 0.2, 2);
  MagsacStatistics stats;
  const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, scene.p1, {}, {}, &stats);
  ASSERT_TRUE(result.success);
  ASSERT_EQ(result.inlier_mask.size(), scene.p0.size());
  const Kept kept = Count(scene, result);
  EXPECT_GT(kept.inliers, 170) << outliers << " outliers";
  EXPECT_LE(kept.outliers, 1 + outliers / 100) << outliers << " outliers";
  EXPECT_EQ(result.num_inliers, kept.inliers + kept.outliers);
  EXPECT_LT(MeanTrueError(scene, result.F, 0, 200), 0.25);
  EXPECT_FALSE(stats.stopped_early);
  // The confidence criterion of the model found, not the cap, ended the loop.
  EXPECT_LE(stats.iterations, SamplesToSettle(0.8 * 200.0 / (200 + outliers), 0.999, 100000));
}

INSTANTIATE_TEST_SUITE_P(Shares, MagsacOutliers, ::testing::Values(0, 50, 200, 300));

// OpenCV's USAC_MAGSAC is the reference: on the same data, the share of inliers agrees within a few matches.
TEST(Magsac, AgreesWithOpenCv) {
  for (unsigned seed : {3u, 4u, 5u}) {
    const Scene scene = MakeScene(150, 150, 0.4, seed);
    VerifierOptions options;
    const FundamentalResult opencv = EstimateFundamental(scene.p0, scene.p1, options);
    const FundamentalResult own = EstimateFundamentalMagsac(scene.p0, scene.p1, options);
    ASSERT_TRUE(opencv.success && own.success);
    EXPECT_NEAR(own.num_inliers, opencv.num_inliers, 0.04 * scene.p0.size()) << "scene " << seed;
    EXPECT_LT(ModelDistance(own.F, scene.F_true), 5 * ModelDistance(opencv.F, scene.F_true) + 0.02);
  }
}

// Four fifths of the scene on one plane: a 7-point sample with five plane points gives models that explain the
// plane and miss the rest (DEGENSAC's case); the points off the plane must be kept too.
TEST(Magsac, DominantPlaneDoesNotHideTheRestOfTheScene) {
  const Scene scene = MakeScene(250, 100, 0.2, 6, /*on_plane=*/200);
  for (int seed : {0, 1, 2}) {
    VerifierOptions options;
    options.seed = seed;
    const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, scene.p1, options);
    ASSERT_TRUE(result.success);
    int off_plane_kept = 0;
    for (int i = 200; i < 250; ++i) off_plane_kept += result.inlier_mask[i];
    EXPECT_GE(off_plane_kept, 40) << "seed " << seed;
    EXPECT_LT(MeanTrueError(scene, result.F, 200, 250), 0.3) << "seed " << seed;
  }
}

TEST(Magsac, DegenerateInputFailsCleanly) {
  EXPECT_FALSE(EstimateFundamentalMagsac({}, {}, {}).success);
  const Scene few = MakeScene(7, 0, 0.0, 7);
  EXPECT_FALSE(EstimateFundamentalMagsac(few.p0, few.p1, {}).success);
  // Every correspondence the same point: no 7-point system of rank 7.
  const std::vector<cv::Point2f> same(50, cv::Point2f(100, 100)), other(50, cv::Point2f(120, 90));
  EXPECT_FALSE(EstimateFundamentalMagsac(same, other, {}).success);
  // Points on one line in both images.
  std::vector<cv::Point2f> line0, line1;
  for (int i = 0; i < 60; ++i) {
    line0.emplace_back(10.f + 5 * i, 20.f + 2 * i);
    line1.emplace_back(30.f + 4 * i, 40.f + 3 * i);
  }
  const FundamentalResult collinear = EstimateFundamentalMagsac(line0, line1, {});
  if (collinear.success) {
    EXPECT_EQ(collinear.inlier_mask.size(), line0.size());
  }
}

// A frame repeated (or a robot standing still): every point where it was. Like OpenCV's USAC, the estimate
// succeeds with every unmoved point an inlier, so that Algorithm 1 sees S = 1 and makes no key image of it;
// most points that moved are outliers.
TEST(Magsac, UnmovedPointsAreInliers) {
  const Scene scene = MakeScene(150, 0, 0.0, 5);
  std::vector<cv::Point2f> p1 = scene.p0;
  for (int i = 0; i < 15; ++i) p1[i] += cv::Point2f(40.f + i, -25.f);  // a few that moved
  const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, p1, {});
  ASSERT_TRUE(result.success);
  // Every unmoved point fits; of the moved ones only those that happened to move along a line through the
  // epipole can.
  for (size_t i = 15; i < p1.size(); ++i) EXPECT_TRUE(result.inlier_mask[i]) << i;
  EXPECT_LT(result.num_inliers, 150);
  const cv::Mat F = cv::findFundamentalMat(scene.p0, p1, cv::USAC_MAGSAC, 1.0, 0.999, 100000);
  EXPECT_FALSE(F.empty()) << "OpenCV accepts the same input";
}

// A scene that is one plane only: F is not unique, but every correspondence fits the model returned.
TEST(Magsac, PlanarSceneGivesAConsistentModel) {
  const Scene scene = MakeScene(120, 0, 0.1, 8, /*on_plane=*/120);
  const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, scene.p1, {});
  ASSERT_TRUE(result.success);
  EXPECT_GE(result.num_inliers, 110);
}

TEST(Magsac, SameSeedSameResultOtherSeedSameGeometry) {
  const Scene scene = MakeScene(120, 120, 0.3, 9);
  VerifierOptions options;
  const FundamentalResult a = EstimateFundamentalMagsac(scene.p0, scene.p1, options);
  const FundamentalResult b = EstimateFundamentalMagsac(scene.p0, scene.p1, options);
  ASSERT_TRUE(a.success);
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(cv::norm(cv::Mat(a.F), cv::Mat(b.F), cv::NORM_INF), 0.0);
  options.seed = 17;
  const FundamentalResult c = EstimateFundamentalMagsac(scene.p0, scene.p1, options);
  ASSERT_TRUE(c.success);
  EXPECT_NEAR(c.num_inliers, a.num_inliers, 6);
  EXPECT_LT(MeanTrueError(scene, a.F, 0, 120), 0.3);
  EXPECT_LT(MeanTrueError(scene, c.F, 0, 120), 0.3);
}

// The result does not depend on the order of the correspondences: a link verified again from its stored
// matches (verified first) continues the very run that decided it.
TEST(Magsac, OrderOfTheCorrespondencesDoesNotMatter) {
  const Scene scene = MakeScene(100, 100, 0.3, 13);
  std::vector<int> order(scene.p0.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(order.size() - 1 - i);
  std::swap(order[3], order[150]);
  std::vector<cv::Point2f> p0, p1;
  for (int i : order) {
    p0.push_back(scene.p0[i]);
    p1.push_back(scene.p1[i]);
  }
  const FundamentalResult a = EstimateFundamentalMagsac(scene.p0, scene.p1, {});
  const FundamentalResult b = EstimateFundamentalMagsac(p0, p1, {});
  ASSERT_TRUE(a.success && b.success);
  EXPECT_EQ(cv::norm(cv::Mat(a.F), cv::Mat(b.F), cv::NORM_INF), 0.0);
  for (size_t i = 0; i < order.size(); ++i) EXPECT_EQ(b.inlier_mask[i], a.inlier_mask[order[i]]);
}

TEST(Magsac, SamplesToSettle) {
  EXPECT_EQ(SamplesToSettle(0.5, 0.999, 100000), 881);     // ln(0.001) / ln(1 - 0.5^7) = 880.7
  EXPECT_EQ(SamplesToSettle(0.3, 0.999, 100000), 31583);   // 31582.1
  EXPECT_EQ(SamplesToSettle(0.8, 0.999, 100000), 30);      // 29.3
  EXPECT_EQ(SamplesToSettle(0.1, 0.999, 100000), 100000);  // 6.9 million: the cap
  EXPECT_EQ(SamplesToSettle(0.0, 0.999, 100000), 100000);
  EXPECT_EQ(SamplesToSettle(1.0, 0.999, 100000), 1);
}

int AtLeast(double tau, int n) { return static_cast<int>(std::ceil(tau * n)); }

EarlyStop Targets(std::vector<int> min_inliers) {
  EarlyStop early_stop;
  early_stop.min_inliers = std::move(min_inliers);
  return early_stop;
}

// A pair far above tau: the first good model settles it, long before the confidence criterion would.
TEST(MagsacEarlyStop, StopsOnceEveryTargetIsReached) {
  const Scene scene = MakeScene(240, 60, 0.2, 10);  // 80 % inliers, ~75 % within 0.5 px
  const int n = static_cast<int>(scene.p0.size());
  MagsacStatistics exhaustive, early;
  EstimateFundamentalMagsac(scene.p0, scene.p1, {}, {}, &exhaustive);
  const FundamentalResult result =
      EstimateFundamentalMagsac(scene.p0, scene.p1, {}, Targets({AtLeast(0.5, n)}), &early);
  ASSERT_TRUE(result.success);
  EXPECT_GE(result.num_inliers, AtLeast(0.5, n));
  EXPECT_TRUE(early.stopped_early);
  EXPECT_LT(early.iterations, exhaustive.iterations);
}

// A pair below tau: "no" is settled once the samples that tau's inlier ratio needs have been drawn, exactly.
TEST(MagsacEarlyStop, FailsAfterTheSamplesTheTargetNeeds) {
  const Scene scene = MakeScene(210, 90, 0.2, 11);  // 70 % inliers, about 64 % within 0.5 px
  const int n = static_cast<int>(scene.p0.size());
  MagsacStatistics stats;
  const int target = AtLeast(0.75, n);
  const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, scene.p1, {}, Targets({target}), &stats);
  EXPECT_LT(result.num_inliers, target);
  EXPECT_TRUE(stats.stopped_early);
  EXPECT_EQ(stats.iterations, SamplesToSettle(static_cast<double>(target) / n, 0.999, 100000));

  // With a second target below the inlier ratio, the pair passes it early and the stricter one still decides
  // when to stop; the answer for the lower one is "yes".
  MagsacStatistics two_stats;
  const FundamentalResult two =
      EstimateFundamentalMagsac(scene.p0, scene.p1, {}, Targets({AtLeast(0.3, n), target}), &two_stats);
  ASSERT_TRUE(two.success);
  EXPECT_GE(two.num_inliers, AtLeast(0.3, n));
  EXPECT_EQ(two_stats.iterations, stats.iterations);
}

// A target far above the pair's inlier ratio is rejected after max_samples_to_reject samples when the confidence
// criterion would draw more; set to max_iterations, the criterion alone decides.
TEST(MagsacEarlyStop, RejectsAfterAtMostMaxSamplesToReject) {
  const Scene scene = MakeScene(60, 240, 0.2, 13);  // 20 % inliers
  const int n = static_cast<int>(scene.p0.size());
  const int target = AtLeast(0.3, n);
  VerifierOptions options;
  options.max_samples_to_reject = 2000;
  MagsacStatistics capped, criterion;
  const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, scene.p1, options, Targets({target}), &capped);
  EXPECT_LT(result.num_inliers, target);
  EXPECT_TRUE(capped.stopped_early);
  EXPECT_EQ(capped.iterations, 2000);

  options.max_samples_to_reject = options.max_iterations;
  EstimateFundamentalMagsac(scene.p0, scene.p1, options, Targets({target}), &criterion);
  EXPECT_EQ(criterion.iterations, SamplesToSettle(static_cast<double>(target) / n, 0.999, 100000));
  EXPECT_GT(criterion.iterations, 30000);
}

// Targets no model can reach (more inliers than points) are settled before any sample is drawn.
TEST(MagsacEarlyStop, ImpossibleTargetsNeedNoSample) {
  const Scene scene = MakeScene(100, 0, 0.0, 12);
  MagsacStatistics stats;
  const FundamentalResult result = EstimateFundamentalMagsac(scene.p0, scene.p1, {}, Targets({101}), &stats);
  EXPECT_FALSE(result.success);
  EXPECT_EQ(stats.iterations, 0);
}

// A run resumed from an early stop's checkpoint, without targets, is the exhaustive run from the start: the same
// model, inliers and sample count, bit for bit, whichever order the correspondences come in.
TEST(MagsacEarlyStop, ResumedRunIsTheExhaustiveRun) {
  for (int inliers : {120, 200, 260}) {
    const Scene scene = MakeScene(inliers, 300 - inliers, 0.3, 30 + inliers);
    const int n = static_cast<int>(scene.p0.size());
    MagsacStatistics exhaustive_stats, early_stats, resumed_stats;
    const FundamentalResult exhaustive = EstimateFundamentalMagsac(scene.p0, scene.p1, {}, {}, &exhaustive_stats);
    const FundamentalResult early =
        EstimateFundamentalMagsac(scene.p0, scene.p1, {}, Targets({AtLeast(0.2, n), AtLeast(0.95, n)}), &early_stats);
    ASSERT_TRUE(early_stats.stopped_early) << inliers;
    ASSERT_NE(early.checkpoint, nullptr);
    EXPECT_LT(early_stats.iterations, exhaustive_stats.iterations);

    std::vector<cv::Point2f> reversed0(scene.p0.rbegin(), scene.p0.rend());
    std::vector<cv::Point2f> reversed1(scene.p1.rbegin(), scene.p1.rend());
    EarlyStop resume;
    resume.resume_from = early.checkpoint;
    const FundamentalResult resumed = EstimateFundamentalMagsac(reversed0, reversed1, {}, resume, &resumed_stats);
    ASSERT_TRUE(resumed.success);
    EXPECT_EQ(resumed.F, exhaustive.F) << inliers;
    EXPECT_EQ(resumed.num_inliers, exhaustive.num_inliers);
    EXPECT_EQ(std::vector<unsigned char>(resumed.inlier_mask.rbegin(), resumed.inlier_mask.rend()),
              exhaustive.inlier_mask);
    EXPECT_EQ(resumed_stats.iterations, exhaustive_stats.iterations);
    EXPECT_EQ(resumed_stats.models_scored, exhaustive_stats.models_scored);
    EXPECT_FALSE(resumed_stats.stopped_early);
    EXPECT_EQ(resumed.checkpoint, nullptr);  // it ran to the end
  }
}

// A checkpoint belongs to its points and options: resuming with others is a programming error.
TEST(MagsacEarlyStop, ResumingAnotherRunThrows) {
  const Scene scene = MakeScene(200, 100, 0.3, 40);
  const FundamentalResult early = EstimateFundamentalMagsac(scene.p0, scene.p1, {}, Targets({60}));
  ASSERT_NE(early.checkpoint, nullptr);
  EarlyStop resume;
  resume.resume_from = early.checkpoint;
  std::vector<cv::Point2f> moved = scene.p1;
  moved[5].x += 1.0f;
  EXPECT_THROW(EstimateFundamentalMagsac(scene.p0, moved, {}, resume), std::logic_error);
  VerifierOptions other_seed;
  other_seed.seed = 1;
  EXPECT_THROW(EstimateFundamentalMagsac(scene.p0, scene.p1, other_seed, resume), std::logic_error);
}

// Stopping early changes the answer to "S >= tau?" no more than a change of seed does: on scenes whose
// inlier ratio lies on both sides of each tau, compare with the exhaustive run.
TEST(MagsacEarlyStop, DecisionsAgreeWithTheExhaustiveRun) {
  const std::vector<double> taus = {0.3, 0.5, 0.7};
  int decisions = 0, flips = 0;
  for (int inliers : {60, 110, 160, 210, 260}) {
    const Scene scene = MakeScene(inliers, 300 - inliers, 0.2, 20 + inliers);
    const int n = static_cast<int>(scene.p0.size());
    EarlyStop early;
    for (double tau : taus) early.min_inliers.push_back(AtLeast(tau, n));
    const FundamentalResult full = EstimateFundamentalMagsac(scene.p0, scene.p1, {});
    const FundamentalResult fast = EstimateFundamentalMagsac(scene.p0, scene.p1, {}, early);
    for (int target : early.min_inliers) {
      ++decisions;
      flips += (full.num_inliers >= target) != (fast.num_inliers >= target);
    }
  }
  EXPECT_EQ(decisions, 15);
  EXPECT_LE(flips, 1);
}

// Real ORB matches from ../shared: S of vmap's estimator against OpenCV's, both averaged over three seeds.
// Scores that favour the inliers, as a matcher's similarities do, with overlap: an outlier may outscore an inlier.
std::vector<float> ScoresFavouringInliers(const Scene& scene, unsigned seed) {
  cv::RNG rng(seed);
  std::vector<float> scores;
  for (size_t i = 0; i < scene.p0.size(); ++i) {
    const bool inlier = static_cast<int>(i) < scene.inliers;
    scores.push_back(static_cast<float>((inlier ? 0.9 : 0.85) + rng.uniform(-0.05, 0.05)));
  }
  return scores;
}

TEST(MagsacOnBest, FindsTheModelAmongThousandsOfLowRatioMatchesInABoundedLoop) {
  const Scene scene = MakeScene(400, 3600, 0.5, 11);  // 10 % inliers
  const std::vector<float> scores = ScoresFavouringInliers(scene, 12);
  VerifierOptions options;
  options.max_iterations = 1000;
  options.loop_points = 512;
  MagsacStatistics statistics;
  const FundamentalResult result = EstimateFundamentalMagsacOnBest(scene.p0, scene.p1, scores, options, &statistics);
  ASSERT_TRUE(result.success);
  EXPECT_LE(statistics.iterations, options.max_iterations);
  // Refined on all: as many inliers as the true F keeps, those outside the 512 best-scored matches too.
  int true_inliers = 0;
  for (int i = 0; i < scene.inliers; ++i) true_inliers += SampsonDistance(scene.F_true, scene.p0[i], scene.p1[i]) < 0.5;
  const Kept kept = Count(scene, result);
  EXPECT_GE(kept.inliers, 0.9 * true_inliers);
  EXPECT_GT(kept.inliers, 200);
  EXPECT_LE(kept.outliers, 20);
  EXPECT_LT(MeanTrueError(scene, result.F, 0, scene.inliers), 0.5);
  // The same budget on every match does not find it: 1,000 samples at a ratio of 0.1.
  options.loop_points = 0;
  const FundamentalResult everything = EstimateFundamentalMagsacOnBest(scene.p0, scene.p1, scores, options);
  EXPECT_LT(everything.num_inliers, 300);
}

TEST(MagsacOnBest, IndependentOfTheOrderAndTheSameAsTheFullRunWithoutScores) {
  const Scene scene = MakeScene(300, 700, 0.5, 21);
  const std::vector<float> scores = ScoresFavouringInliers(scene, 22);
  VerifierOptions options;
  options.loop_points = 256;
  const FundamentalResult result = EstimateFundamentalMagsacOnBest(scene.p0, scene.p1, scores, options);
  ASSERT_TRUE(result.success);
  // Reversed input: the same subset, the same run, the same inliers.
  std::vector<cv::Point2f> p0(scene.p0.rbegin(), scene.p0.rend()), p1(scene.p1.rbegin(), scene.p1.rend());
  const std::vector<float> reversed_scores(scores.rbegin(), scores.rend());
  const FundamentalResult reversed = EstimateFundamentalMagsacOnBest(p0, p1, reversed_scores, options);
  ASSERT_EQ(reversed.num_inliers, result.num_inliers);
  for (size_t i = 0; i < result.inlier_mask.size(); ++i) {
    EXPECT_EQ(result.inlier_mask[i], reversed.inlier_mask[result.inlier_mask.size() - 1 - i]) << i;
  }
  // Without a score per match, or with fewer matches than loop_points, it is the full run.
  const FundamentalResult full = EstimateFundamentalMagsac(scene.p0, scene.p1, options);
  EXPECT_EQ(EstimateFundamentalMagsacOnBest(scene.p0, scene.p1, {}, options).inlier_mask, full.inlier_mask);
  options.loop_points = 2000;
  EXPECT_EQ(EstimateFundamentalMagsacOnBest(scene.p0, scene.p1, scores, options).inlier_mask, full.inlier_mask);
}

TEST(MagsacOnBest, ChosenThroughEstimateFundamentalForScoredMatchesWithoutTargets) {
  const Scene scene = MakeScene(300, 700, 0.5, 31);
  const std::vector<float> scores = ScoresFavouringInliers(scene, 32);
  VerifierOptions options;
  options.loop_points = 256;
  options.max_samples_to_reject = 2000;  // the bounded loop's samples
  VerifierOptions bounded = options;
  bounded.max_iterations = 2000;
  EXPECT_EQ(EstimateFundamental(scene.p0, scene.p1, options, {}, &scores).inlier_mask,
            EstimateFundamentalMagsacOnBest(scene.p0, scene.p1, scores, bounded).inlier_mask);
  // Without scores, the verifier as configured (here OpenCV's USAC_MAGSAC).
  EXPECT_EQ(EstimateFundamental(scene.p0, scene.p1, options).inlier_mask,
            EstimateFundamental(scene.p0, scene.p1, VerifierOptions()).inlier_mask);
  options.own_magsac = true;
  EarlyStop targets;
  targets.min_inliers = {100};
  EXPECT_EQ(EstimateFundamental(scene.p0, scene.p1, options, targets, &scores).inlier_mask,
            EstimateFundamentalMagsac(scene.p0, scene.p1, options, targets).inlier_mask);
  options.loop_points = 8;
  EXPECT_THROW(options.Check(), OptionError);
}

TEST(Magsac, AgreesWithOpenCvOnRealPairs) {
  const std::filesystem::path shared = testing::SharedDir();
  if (shared.empty()) GTEST_SKIP() << "../shared not found";
  FrameSourceOptions source_options;
  source_options.first = 19;
  source_options.last = 37;
  auto source = OpenFrameSource((shared / "data/rccar_room/images").string(), source_options);
  const auto matcher = CreateOrbMatcher({});
  std::vector<std::shared_ptr<const ImageFeatures>> features;
  while (auto frame = source->Next()) features.push_back(matcher->Extract(frame->gray));
  ASSERT_EQ(features.size(), 19u);
  for (int gap : {1, 5, 18}) {  // S about 0.6, 0.55 and 0.3
    const TentativeMatches matches = matcher->Match(*features[0], *features[gap]);
    double opencv = 0, own = 0;
    for (int seed = 0; seed < 3; ++seed) {
      VerifierOptions options;
      options.seed = seed;
      opencv += EstimateFundamental(matches.points0, matches.points1, options).num_inliers / 3.0;
      own += EstimateFundamentalMagsac(matches.points0, matches.points1, options).num_inliers / 3.0;
    }
    EXPECT_NEAR(own / matches.size(), opencv / matches.size(), 0.03) << "frames 19 and " << 19 + gap;
  }
}

}  // namespace
}  // namespace vmap
