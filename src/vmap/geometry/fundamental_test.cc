#include "vmap/geometry/fundamental.h"

#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {

namespace {

// Random 3-D points seen by two cameras, plus a share of random outliers.
void MakeCorrespondences(int inliers, int outliers, std::vector<cv::Point2f>* p0, std::vector<cv::Point2f>* p1,
                         cv::Matx33d* F_true) {
  cv::RNG rng(11);
  const cv::Matx33d K(500, 0, 320, 0, 500, 240, 0, 0, 1);
  testing::CameraPose a, b;
  b.t = cv::Vec3d(-0.3, 0.02, -0.1);
  *F_true = testing::TrueFundamental(K, a, b);
  for (int i = 0; i < inliers; ++i) {
    const cv::Vec3d X(rng.uniform(-3.0, 3.0), rng.uniform(-2.0, 2.0), rng.uniform(4.0, 12.0));
    const cv::Vec3d x0 = K * X, x1 = K * (X + b.t);
    p0->emplace_back(x0[0] / x0[2] + rng.gaussian(0.2), x0[1] / x0[2] + rng.gaussian(0.2));
    p1->emplace_back(x1[0] / x1[2] + rng.gaussian(0.2), x1[1] / x1[2] + rng.gaussian(0.2));
  }
  for (int i = 0; i < outliers; ++i) {
    p0->emplace_back(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f));
    p1->emplace_back(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f));
  }
}

}  // namespace

class FundamentalByMethod : public ::testing::TestWithParam<std::string> {};

TEST_P(FundamentalByMethod, RecoversTheTrueGeometryAndRejectsOutliers) {
  std::vector<cv::Point2f> p0, p1;
  cv::Matx33d F_true;
  MakeCorrespondences(200, 60, &p0, &p1, &F_true);
  VerifierOptions options;
  options.method = ParseVerifierMethod(GetParam());
  options.threshold = 1.0;
  const FundamentalResult result = EstimateFundamental(p0, p1, options);
  ASSERT_TRUE(result.success);
  ASSERT_EQ(result.inlier_mask.size(), p0.size());
  int true_inliers_kept = 0, outliers_kept = 0;
  for (size_t i = 0; i < p0.size(); ++i) {
    if (!result.inlier_mask[i]) continue;
    (i < 200 ? true_inliers_kept : outliers_kept)++;
    // Every kept match is consistent with the TRUE geometry, not just with the estimate.
  }
  EXPECT_GT(true_inliers_kept, 170);
  EXPECT_LT(outliers_kept, 6);
  EXPECT_EQ(result.num_inliers, true_inliers_kept + outliers_kept);
  double error = 0;
  for (int i = 0; i < 200; ++i) error += SampsonDistance(result.F, p0[i], p1[i]);
  EXPECT_LT(error / 200, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Methods, FundamentalByMethod, ::testing::Values("magsac", "ransac", "usac", "accurate"));

TEST(Fundamental, SameSeedSameResult) {
  std::vector<cv::Point2f> p0, p1;
  cv::Matx33d F_true;
  MakeCorrespondences(120, 120, &p0, &p1, &F_true);
  const VerifierOptions options;
  const FundamentalResult a = EstimateFundamental(p0, p1, options);
  const FundamentalResult b = EstimateFundamental(p0, p1, options);
  ASSERT_TRUE(a.success);
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(cv::norm(cv::Mat(a.F), cv::Mat(b.F)), 0.0);
}

TEST(Fundamental, TooFewMatchesFail) {
  std::vector<cv::Point2f> p0, p1;
  cv::Matx33d F_true;
  MakeCorrespondences(7, 0, &p0, &p1, &F_true);
  EXPECT_FALSE(EstimateFundamental(p0, p1, {}).success);
  EXPECT_FALSE(EstimateFundamental({}, {}, {}).success);
}

TEST(Fundamental, SampsonDistanceIsZeroOnTheEpipolarLine) {
  std::vector<cv::Point2f> p0, p1;
  cv::Matx33d F_true;
  MakeCorrespondences(1, 0, &p0, &p1, &F_true);
  EXPECT_LT(SampsonDistance(F_true, p0[0], p1[0]), 1.5);
  EXPECT_GT(SampsonDistance(F_true, p0[0], p1[0] + cv::Point2f(0, 40)), 5.0);
}

TEST(Fundamental, OptionsAndNamesAreChecked) {
  EXPECT_THROW(ParseVerifierMethod("lmeds"), InputError);
  VerifierOptions options;
  options.threshold = 0;
  EXPECT_THROW(options.Check(), InputError);
  options = {};
  options.confidence = 1.0;
  EXPECT_THROW(options.Check(), InputError);
  for (const char* name : {"magsac", "ransac", "usac", "accurate"}) {
    EXPECT_EQ(VerifierMethodName(ParseVerifierMethod(name)), name);
  }
}

}  // namespace vmap
