#include "vmap/geometry/heading.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/numeric.h"
#include "vmap/evaluation/heading_labels.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/shared_data.h"

namespace vmap {
namespace {

// Matches whose horizontal displacement is `shift` (give or take `jitter`) for `right` of them, and uniformly
// anywhere in +-width for the `wrong` ones, as tentative matches across seasons look.
struct SyntheticMatches {
  std::vector<cv::Point2f> points0, points1;
};
SyntheticMatches MakeMatches(double shift, int right, int wrong, double jitter, unsigned seed, double width = 1024,
                             double height = 384) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> x(0, width), y(0, height), noise(-jitter, jitter);
  SyntheticMatches m;
  for (int i = 0; i < right + wrong; ++i) {
    const cv::Point2f p(x(random), y(random));
    m.points0.push_back(p);
    if (i < right) {
      m.points1.emplace_back(p.x + shift + noise(random), p.y + noise(random));
    } else {
      m.points1.emplace_back(x(random), y(random));
    }
  }
  return m;
}

TEST(Heading, FindsTheShiftThatAMinorityOfMatchesAgreeOn) {
  for (double shift : {-230.0, -12.5, 0.0, 41.0, 300.0}) {
    // 25 right matches among 175 wrong ones: 12.5 %, far under a majority.
    const SyntheticMatches m = MakeMatches(shift, 25, 175, 3.0, 11);
    const HeadingEstimate h = EstimateHeading(m.points0, m.points1, HeadingOptions());
    ASSERT_TRUE(h.valid());
    EXPECT_EQ(HeadingMethodName(h.method), "displacement_mode");
    EXPECT_NEAR(h.px, shift, 3.0);
    EXPECT_GE(h.votes, 25);
    EXPECT_EQ(h.num_voters, 200);
    EXPECT_NEAR(h.confidence, double(h.votes) / 200, 1e-12);
    EXPECT_TRUE(std::isnan(h.deg)) << "no camera, no degrees";
  }
}

TEST(Heading, DoesNotDependOnTheOrderOfTheMatches) {
  SyntheticMatches m = MakeMatches(-60.0, 20, 80, 4.0, 5);
  const HeadingEstimate a = EstimateHeading(m.points0, m.points1, HeadingOptions());
  std::vector<int> order(m.points0.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  SyntheticMatches shuffled;
  for (int i : order) {
    shuffled.points0.push_back(m.points0[i]);
    shuffled.points1.push_back(m.points1[i]);
  }
  const HeadingEstimate b = EstimateHeading(shuffled.points0, shuffled.points1, HeadingOptions());
  EXPECT_EQ(a.px, b.px);
  EXPECT_EQ(a.votes, b.votes);
}

TEST(Heading, GivesNoEstimateWhenTooFewMatchesAgree) {
  HeadingOptions options;
  options.min_votes = 5;
  const SyntheticMatches m = MakeMatches(10.0, 4, 0, 1.0, 1);
  const HeadingEstimate h = EstimateHeading(m.points0, m.points1, options);
  EXPECT_FALSE(h.valid());
  EXPECT_TRUE(std::isnan(h.px));
  EXPECT_EQ(h.confidence, 0.0);
  EXPECT_FALSE(EstimateHeading({}, {}, HeadingOptions()).valid());
}

TEST(Heading, RightMatchesAgreeInVerticalDisplacementToo) {
  // 20 right matches at +50 px; 30 wrong ones that happen to agree on -200 px but move up or down anyhow.
  SyntheticMatches m = MakeMatches(50.0, 20, 0, 2.0, 9);
  const SyntheticMatches wrong = MakeMatches(-200.0, 30, 0, 2.0, 10);
  std::mt19937 random(12);
  std::uniform_real_distribution<double> dy(-150, 150);
  for (size_t i = 0; i < wrong.points0.size(); ++i) {
    m.points0.push_back(wrong.points0[i]);
    m.points1.push_back(wrong.points1[i] + cv::Point2f(0, dy(random)));
  }
  HeadingOptions by_x_alone;
  by_x_alone.window_dy_px = 0.0;
  EXPECT_NEAR(EstimateHeading(m.points0, m.points1, by_x_alone).px, -200.0, 3.0);
  const HeadingEstimate h = EstimateHeading(m.points0, m.points1, HeadingOptions());
  EXPECT_NEAR(h.px, 50.0, 3.0);
  EXPECT_EQ(h.num_voters, 50);
  EXPECT_GE(h.votes, 20);
  EXPECT_LT(h.votes, 25) << "few of the wrong ones fall into the right window";
}

TEST(Heading, WhereFKeepsManyMatchesTheirMedianIsTheHeading) {
  // 60 verified matches at -20 px (give or take 6), among 200 tentative ones of which 40 wrong ones happen to
  // agree on +90 px: the verified ones decide.
  SyntheticMatches m = MakeMatches(-20.0, 60, 100, 6.0, 31);
  const SyntheticMatches chance = MakeMatches(90.0, 40, 0, 1.0, 32);
  m.points0.insert(m.points0.end(), chance.points0.begin(), chance.points0.end());
  m.points1.insert(m.points1.end(), chance.points1.begin(), chance.points1.end());
  std::vector<unsigned char> verified(m.points0.size(), 0);
  std::fill(verified.begin(), verified.begin() + 60, 1);
  std::vector<double> verified_dx;
  for (int i = 0; i < 60; ++i) verified_dx.push_back(m.points1[i].x - m.points0[i].x);
  HeadingOptions options;
  options.min_verified = 50;
  const HeadingEstimate h = EstimateHeading(m.points0, m.points1, verified, options);
  EXPECT_EQ(h.method, HeadingMethod::kVerifiedMedian);
  EXPECT_EQ(h.px, Median(verified_dx));
  EXPECT_EQ(h.votes, 60);
  EXPECT_EQ(h.num_voters, 200);
  EXPECT_DOUBLE_EQ(h.confidence, 0.3);
  // Fewer verified matches than min_verified, or no F at all: the mode of all matches.
  options.min_verified = 61;
  const HeadingEstimate mode = EstimateHeading(m.points0, m.points1, verified, options);
  EXPECT_EQ(mode.method, HeadingMethod::kDisplacementMode);
  EXPECT_EQ(mode.px, EstimateHeading(m.points0, m.points1, options).px);
  EXPECT_EQ(EstimateHeading(m.points0, m.points1, {}, options).method, HeadingMethod::kDisplacementMode);
}

TEST(Heading, WithACameraGivesTheBearingOfTheShift) {
  const Camera camera = Camera::Make(800, 800, 512, 192);
  // Points shifted by a pure rotation about the camera's y axis: x_n' = tan(atan(x_n) + yaw).
  const double yaw = 3.0 * M_PI / 180.0;
  std::mt19937 random(4);
  std::uniform_real_distribution<double> x(100, 900), y(0, 384);
  std::vector<cv::Point2f> points0, points1;
  for (int i = 0; i < 60; ++i) {
    const double x0 = x(random), y0 = y(random);
    const double xn = (x0 - camera.cx) / camera.fx;
    points0.emplace_back(x0, y0);
    points1.emplace_back(camera.cx + camera.fx * std::tan(std::atan(xn) + yaw), y0);
  }
  HeadingOptions options;
  options.window_px = 60.0;  // a rotation's pixel shift grows towards the image's sides
  const HeadingEstimate h = EstimateHeading(points0, points1, options, &camera);
  ASSERT_TRUE(h.valid());
  EXPECT_NEAR(h.deg, 3.0, 1e-3);
  EXPECT_GT(h.px, camera.fx * std::tan(yaw) - 1.0) << "pixels and degrees agree";
}

TEST(Heading, OptionsCheckNamesTheBadField) {
  HeadingOptions options;
  options.window_px = 0.0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "window_px");
  options = HeadingOptions();
  options.window_dy_px = -1.0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "window_dy_px");
  options = HeadingOptions();
  options.min_votes = 0;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "min_votes");
  options = HeadingOptions();
  options.min_verified = -1;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "min_verified");
  EXPECT_NO_THROW(HeadingOptions().Check());
}

// A textured scene, and two views of it cropped `offset` px apart: a scene point at X appears at X - a in a
// crop starting at a, so x in the second minus x in the first is a0 - a1.
cv::Mat TexturedScene(cv::Size size, unsigned seed) {
  cv::RNG random(seed);
  cv::Mat scene(size, CV_8U, cv::Scalar(128));
  for (int i = 0; i < 400; ++i) {
    const cv::Point corner(random.uniform(0, size.width), random.uniform(0, size.height));
    const cv::Size extent(random.uniform(4, 40), random.uniform(4, 40));
    cv::rectangle(scene, cv::Rect(corner, extent), cv::Scalar(random.uniform(0, 256)), cv::FILLED);
    cv::circle(scene, cv::Point(random.uniform(0, size.width), random.uniform(0, size.height)), random.uniform(3, 15),
               cv::Scalar(random.uniform(0, 256)), cv::FILLED);
  }
  cv::GaussianBlur(scene, scene, cv::Size(3, 3), 0.8);
  return scene;
}

TEST(Heading, FindsTheShiftBetweenTwoCropsOfAScene_DarkerAndNoisy) {
  const cv::Mat scene = TexturedScene(cv::Size(700, 240), 21);
  const OrbMatcherOptions orb_options;
  const auto matcher = CreateOrbMatcher(orb_options);
  for (int a1 : {20, 110, 200, 290}) {
    const int a0 = 150;
    const cv::Mat view0 = scene(cv::Rect(a0, 0, 400, 240)).clone();
    cv::Mat view1;
    scene(cv::Rect(a1, 0, 400, 240)).convertTo(view1, CV_8U, 0.6, 30.0);  // another light
    cv::Mat noise(view1.size(), CV_16S);
    cv::randn(noise, 0, 6);
    view1.convertTo(view1, CV_16S);
    view1 += noise;
    view1.convertTo(view1, CV_8U);
    const TentativeMatches m = matcher->Match(*matcher->Extract(view0), *matcher->Extract(view1));
    const HeadingEstimate h = EstimateHeading(m.points0, m.points1, HeadingOptions());
    ASSERT_TRUE(h.valid());
    EXPECT_NEAR(h.px, a0 - a1, 1.5) << "crops at " << a0 << " and " << a1;
  }
}

// The michigan seasonal pairs of one place (../shared/data/michigan_seasons), a year of seasons apart: with
// vmap's default ORB, the mode of the tentative matches finds the hand-labelled heading (within 35 px) for
// most of them, and for clearly more than the median displacement of the F-verified matches did.
TEST(Heading, FindsTheLabelledHeadingAcrossSeasonsOnMichigan) {
  SKIP_WITHOUT_SHARED();
  const std::string root = testing::SharedDir() + "/data/michigan_seasons/";
  const auto matcher = CreateOrbMatcher(OrbMatcherOptions());
  std::map<std::string, std::shared_ptr<const ImageFeatures>> features;
  auto features_of = [&](const std::string& name) {
    auto& f = features[name];
    if (!f) f = matcher->Extract(cv::imread(root + name, cv::IMREAD_GRAYSCALE));
    return f;
  };
  VerifierOptions verifier;
  verifier.max_iterations = 5000;
  int pairs = 0, mode_correct = 0, verified_correct = 0;
  for (const HeadingLabel& labelled : ReadHeadingLabels(root + "gt.csv")) {
    if (labelled.teach_image.find("02.png") == std::string::npos) continue;  // place 02 only: 66 pairs
    const double label = labelled.dx_px;
    const TentativeMatches m = matcher->Match(*features_of(labelled.teach_image), *features_of(labelled.repeat_image));
    const HeadingEstimate h = EstimateHeading(m.points0, m.points1, HeadingOptions());
    ++pairs;
    if (h.valid() && std::abs(h.px - label) <= 35.0) ++mode_correct;
    if (static_cast<int>(m.size()) < verifier.min_matches) continue;
    const FundamentalResult f = EstimateFundamental(m.points0, m.points1, verifier);
    std::vector<double> verified_dx;
    for (size_t i = 0; i < m.size(); ++i) {
      if (f.success && f.inlier_mask[i]) verified_dx.push_back(m.points1[i].x - m.points0[i].x);
    }
    if (!verified_dx.empty() && std::abs(Median(verified_dx) - label) <= 35.0) ++verified_correct;
  }
  ASSERT_EQ(pairs, 66);
  EXPECT_GE(mode_correct, 0.7 * pairs);
  EXPECT_GE(mode_correct, verified_correct + 0.1 * pairs) << "F-verified median: " << verified_correct << " right";
}

}  // namespace
}  // namespace vmap
