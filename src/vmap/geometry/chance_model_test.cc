#include "vmap/geometry/chance_model.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "vmap/geometry/fundamental.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

const cv::Size kQvga(320, 240);

// `inliers` random 3-D points seen by two cameras 320x240 (image noise `sigma` px), then `outliers` matches
// with both points uniform over the images, shuffled together.
void SceneMatches(int inliers, int outliers, double sigma, int seed, std::vector<cv::Point2f>* p0,
                  std::vector<cv::Point2f>* p1) {
  cv::RNG rng(seed);
  const cv::Matx33d K(300, 0, 160, 0, 300, 120, 0, 0, 1);
  const cv::Vec3d t(-0.25, 0.02, -0.15);
  while (static_cast<int>(p0->size()) < inliers) {
    // Scene points spread over the first image (a textured scene), at depths of 4 to 12 m.
    const double depth = rng.uniform(4.0, 12.0);
    const cv::Vec3d X = depth * (K.inv() * cv::Vec3d(rng.uniform(0.0, 320.0), rng.uniform(0.0, 240.0), 1.0));
    const cv::Vec3d x0 = K * X, x1 = K * (X + t);
    const cv::Point2f a(x0[0] / x0[2] + rng.gaussian(sigma), x0[1] / x0[2] + rng.gaussian(sigma));
    const cv::Point2f b(x1[0] / x1[2] + rng.gaussian(sigma), x1[1] / x1[2] + rng.gaussian(sigma));
    if (!cv::Rect2f(0, 0, kQvga.width, kQvga.height).contains(a) || !cv::Rect2f(0, 0, 320, 240).contains(b)) continue;
    p0->push_back(a);
    p1->push_back(b);
  }
  for (int i = 0; i < outliers; ++i) {
    p0->emplace_back(rng.uniform(0.f, 320.f), rng.uniform(0.f, 240.f));
    p1->emplace_back(rng.uniform(0.f, 320.f), rng.uniform(0.f, 240.f));
  }
  for (int i = static_cast<int>(p0->size()) - 1; i > 0; --i) {
    const int j = rng.uniform(0, i + 1);
    std::swap((*p0)[i], (*p0)[j]);
    std::swap((*p1)[i], (*p1)[j]);
  }
}

// The localizer's verifier: the map's MAGSAC at 0.5 px, iterations capped at 5,000.
VerifierOptions LocalizationVerifier() {
  VerifierOptions options;
  options.max_iterations = 5000;
  return options;
}

TEST(ChanceModel, RandomInlierProbabilityBoundsTheShareOfRandomPointsNearALine) {
  cv::RNG rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    // A random line through the image.
    const cv::Point2d a(rng.uniform(0.0, 320.0), rng.uniform(0.0, 240.0));
    const double angle = rng.uniform(0.0, M_PI);
    const cv::Vec3d line(std::sin(angle), -std::cos(angle), -(std::sin(angle) * a.x - std::cos(angle) * a.y));
    const double e = 2.0;
    int near = 0;
    const int points = 20000;
    for (int i = 0; i < points; ++i) {
      const cv::Point2d p(rng.uniform(0.0, 320.0), rng.uniform(0.0, 240.0));
      near += std::abs(line[0] * p.x + line[1] * p.y + line[2]) <= e;
    }
    // The bound, with room for the sampling error of 20,000 points (a few standard deviations).
    EXPECT_LE(static_cast<double>(near) / points, RandomInlierProbability(e, kQvga) + 0.004) << "trial " << trial;
  }
  EXPECT_NEAR(RandomInlierProbability(1.0, kQvga), 2.0 * 400.0 / (320.0 * 240.0), 1e-12);
  EXPECT_EQ(RandomInlierProbability(1000.0, kQvga), 1.0);
}

TEST(ChanceModel, FalseAlarmsFallWithEachMatchBeyondWhatChanceExplains) {
  for (int n : {20, 100, 1000, 4000}) {
    for (double alpha : {1e-4, 0.005, 0.05}) {
      const int chance_count = static_cast<int>(std::ceil(7 + alpha * (n - 7)));
      double previous = Log10FalseAlarms(n, std::max(8, chance_count), alpha);
      for (int k = std::max(9, chance_count + 1); k <= n; ++k) {
        const double current = Log10FalseAlarms(n, k, alpha);
        ASSERT_LT(current, previous) << "n " << n << " alpha " << alpha << " k " << k;
        previous = current;
      }
    }
  }
  // More matches, a wider strip or more places tried make a count less remarkable.
  EXPECT_LT(Log10FalseAlarms(100, 30, 0.005), Log10FalseAlarms(200, 30, 0.005));
  EXPECT_LT(Log10FalseAlarms(100, 30, 0.005), Log10FalseAlarms(100, 30, 0.01));
  EXPECT_NEAR(Log10FalseAlarms(100, 30, 0.005, 50.0), Log10FalseAlarms(100, 30, 0.005) + std::log10(50.0), 1e-9);
  // F needs 8 matches to be verified at all.
  EXPECT_EQ(Log10FalseAlarms(100, 7, 0.005), std::numeric_limits<double>::infinity());
  EXPECT_EQ(Log10FalseAlarms(10, 11, 0.005), std::numeric_limits<double>::infinity());
}

TEST(ChanceModel, TheScoreIsTheLeastFalseAlarmsOverTheNearestMatches) {
  std::vector<cv::Point2f> p0, p1;
  SceneMatches(40, 120, 0.3, 3, &p0, &p1);
  const FundamentalResult fit = EstimateFundamental(p0, p1, LocalizationVerifier());
  ASSERT_TRUE(fit.success);
  const ChanceOfMatches chance = ChanceOfFundamental(fit.F, p0, p1, kQvga, kQvga, 12.0);
  std::vector<double> distances;
  for (size_t i = 0; i < p0.size(); ++i) distances.push_back(EpipolarDistance(fit.F, p0[i], p1[i]));
  std::sort(distances.begin(), distances.end());
  double least = std::numeric_limits<double>::infinity();
  for (int k = 8; k <= static_cast<int>(distances.size()); ++k) {
    least = std::min(least, Log10FalseAlarms(static_cast<int>(distances.size()), k,
                                             RandomInlierProbability(distances[k - 1], kQvga), 12.0));
  }
  EXPECT_NEAR(chance.log10_nfa, least, 1e-6);
  EXPECT_NEAR(chance.threshold, distances[chance.num_inliers - 1], 1e-12);
  // The 40 scene matches and hardly any of the 120 random ones.
  EXPECT_GE(chance.num_inliers, 36);
  EXPECT_LE(chance.num_inliers, 46);
}

// Points that crowd into a corner lie near many epipolar lines there: the pair's own points paired at random
// (all 9,900 ordered pairings of 100 matches) then explain more than points spread over the image would, and
// the score takes the larger share.
// The score written out plainly: every pairing of a frame point with another match's key point (the pairs
// are few enough for ChanceOfFundamental to take them all), counted at each threshold. `crowded`: thresholds
// where the pairings explain more than uniform points would.
double LeastFalseAlarmsOverAllPairings(const cv::Matx33d& F, const std::vector<cv::Point2f>& p0,
                                       const std::vector<cv::Point2f>& p1, double hypotheses, int* crowded) {
  const int n = static_cast<int>(p0.size());
  std::vector<double> distances, paired;
  for (int i = 0; i < n; ++i) {
    distances.push_back(std::max(EpipolarDistance(F, p0[i], p1[i]), 1e-4));
    for (int j = 0; j < n; ++j) {
      if (j != i) paired.push_back(EpipolarDistance(F, p0[i], p1[j]));
    }
  }
  std::sort(distances.begin(), distances.end());
  double least = std::numeric_limits<double>::infinity();
  *crowded = 0;
  for (int k = 8; k <= n; ++k) {
    const double e = distances[k - 1];
    const double share =
        static_cast<double>(std::count_if(paired.begin(), paired.end(), [&](double d) { return d <= e; })) /
        paired.size();
    const double uniform = RandomInlierProbability(e, kQvga);
    *crowded += share > uniform;
    const double alpha = std::max(uniform, share);
    if (alpha >= 1.0) break;
    least = std::min(least, Log10FalseAlarms(n, k, alpha, hypotheses));
  }
  return least;
}

TEST(ChanceModel, ThePairsOwnPointsPairedAtRandomRaiseAlphaWhereTheyCrowd) {
  std::vector<cv::Point2f> p0, p1;
  SceneMatches(60, 40, 0.3, 5, &p0, &p1);
  for (size_t i = 0; i < p0.size(); ++i) {  // into the top-left quarter: the same geometry, crowded
    p0[i] *= 0.25f;
    p1[i] *= 0.25f;
  }
  const FundamentalResult fit = EstimateFundamental(p0, p1, LocalizationVerifier());
  ASSERT_TRUE(fit.success);
  const ChanceOfMatches chance = ChanceOfFundamental(fit.F, p0, p1, kQvga, kQvga, 12.0);
  int crowded = 0;
  const double least = LeastFalseAlarmsOverAllPairings(fit.F, p0, p1, 12.0, &crowded);
  EXPECT_GT(crowded, static_cast<int>(p0.size()) / 2) << "the crowding is what this test tests";
  EXPECT_NEAR(chance.log10_nfa, least, 1e-6);
}

// A pairing exactly at a match's threshold is within it. A sideways camera (F = [(1, 0, 0)]x: every epipolar
// line is a row) on whole-pixel rows makes every distance a whole number of pixels, so pairings tie with the
// thresholds all the time.
TEST(ChanceModel, PairingsAtAThresholdAreWithinIt) {
  const cv::Matx33d F(0, 0, 0, 0, 0, -1, 0, 1, 0);
  cv::RNG rng(3);
  std::vector<cv::Point2f> p0, p1;
  for (int i = 0; i < 100; ++i) {
    const int row = rng.uniform(0, 60);
    const int offset = i < 70 ? rng.uniform(0, 3) : rng.uniform(-40, 41);
    p0.emplace_back(static_cast<float>(rng.uniform(0, 320)), static_cast<float>(row));
    p1.emplace_back(static_cast<float>(rng.uniform(0, 320)), static_cast<float>(row + offset));
  }
  ASSERT_EQ(EpipolarDistance(F, {10, 5}, {200, 7}), 2.0);
  int crowded = 0;
  const double least = LeastFalseAlarmsOverAllPairings(F, p0, p1, 1.0, &crowded);
  ASSERT_GT(crowded, 0);
  EXPECT_NEAR(ChanceOfFundamental(F, p0, p1, kQvga, kQvga).log10_nfa, least, 1e-6);
}

TEST(ChanceModel, RandomMatchesAreRefused) {
  // Matches with no scene behind them, as many as a pair of unrelated images gives, verified as the localizer
  // does: whatever MAGSAC keeps, chance explains it.
  int verified = 0;
  for (int n : {30, 100, 300, 1000}) {
    for (int seed = 0; seed < 6; ++seed) {
      std::vector<cv::Point2f> p0, p1;
      SceneMatches(0, n, 0.0, 100 + seed, &p0, &p1);
      const FundamentalResult fit = EstimateFundamental(p0, p1, LocalizationVerifier());
      if (!fit.success) continue;
      ++verified;
      const ChanceOfMatches chance = ChanceOfFundamental(fit.F, p0, p1, kQvga, kQvga);
      EXPECT_GT(chance.log10_nfa, 0.0) << n << " random matches (seed " << seed << "), " << fit.num_inliers
                                       << " kept by MAGSAC: " << chance.num_inliers << " within " << chance.threshold
                                       << " px";
    }
  }
  EXPECT_GT(verified, 6) << "MAGSAC found some F in random matches: the test tests something";
}

TEST(ChanceModel, AGenuineSceneIsAcceptedEvenAmongManyOutliers) {
  // 40 matches of one scene among 150 (S 0.27, what the old rule of S >= 0.3 refused), and 300 among 400.
  for (const auto& [inliers, outliers] : {std::pair{40, 110}, std::pair{300, 100}}) {
    std::vector<cv::Point2f> p0, p1;
    SceneMatches(inliers, outliers, 0.4, 9, &p0, &p1);
    const FundamentalResult fit = EstimateFundamental(p0, p1, LocalizationVerifier());
    ASSERT_TRUE(fit.success);
    const ChanceOfMatches chance = ChanceOfFundamental(fit.F, p0, p1, kQvga, kQvga, 100.0);
    EXPECT_LT(chance.log10_nfa, -5.0) << inliers << " of " << inliers + outliers;
    EXPECT_GE(chance.num_inliers, inliers * 8 / 10);
  }
}

TEST(ChanceModel, EpipolarDistanceIsTheLargerPointToLineDistance) {
  const cv::Matx33d K(300, 0, 160, 0, 300, 120, 0, 0, 1);
  testing::CameraPose a, b;
  b.t = cv::Vec3d(-0.3, 0.0, 0.0);  // sideways: horizontal epipolar lines
  const cv::Matx33d F = testing::TrueFundamental(K, a, b);
  EXPECT_NEAR(EpipolarDistance(F, {100, 50}, {80, 50}), 0.0, 1e-9);
  EXPECT_NEAR(EpipolarDistance(F, {100, 50}, {80, 53}), 3.0, 1e-6);
  EXPECT_NEAR(EpipolarDistance(F, {100, 48}, {80, 50}), 2.0, 1e-6);
}

}  // namespace
}  // namespace vmap
