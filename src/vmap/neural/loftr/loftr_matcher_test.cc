// LoFTR behind the Matcher interface: coordinates in the original image, the key-image reuse path, and
// bad input (too small, no CUDA, no matches).

#include "vmap/neural/loftr/loftr_matcher.h"

#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <torch/torch.h>

#include "vmap/core/error.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/testing/golden_util.h"

namespace vmap {
namespace {

using neural::testing::LoadTensorDict;
using neural::testing::SharedDir;

LoftrMatcherOptions CoarseOptions() {
  LoftrMatcherOptions options;
  options.model = "coarse";
  options.weights = SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt";
  return options;
}

std::string PairDir(const std::string& pair) { return SharedDir() + "/golden/loftr_coarse/" + pair; }

TEST(LoftrMatcher, ReproducesReferenceMatchesThroughTheInterface) {
  SKIP_WITHOUT_SHARED();
  MatcherOptions options;
  options.type = "loftr";
  options.Of<LoftrMatcherOptions>() = CoarseOptions();
  auto matcher = CreateMatcher(options);
  EXPECT_EQ(matcher->name(), "loftr");
  const std::string dir = PairDir("labfloor_00100_00130");
  auto f0 = matcher->Extract(cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE));
  auto f1 = matcher->Extract(cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE));
  EXPECT_EQ(f0->num_features(), 30 * 40);
  EXPECT_EQ(f0->image_size(), cv::Size(640, 480));
  const auto matches = matcher->Match(*f0, *f1);
  const auto g = LoadTensorDict(dir + "/golden.pt");
  const auto mkpts0 = g.at("mkpts0_c"), mkpts1 = g.at("mkpts1_c"), mconf = g.at("mconf");
  ASSERT_EQ(static_cast<int64_t>(matches.size()), mkpts0.size(0));
  ASSERT_EQ(matches.scores.size(), matches.size());
  for (size_t k = 0; k < matches.size(); ++k) {
    EXPECT_EQ(matches.points0[k].x, mkpts0[k][0].item<float>());
    EXPECT_EQ(matches.points0[k].y, mkpts0[k][1].item<float>());
    EXPECT_EQ(matches.points1[k].x, mkpts1[k][0].item<float>());
    EXPECT_EQ(matches.points1[k].y, mkpts1[k][1].item<float>());
    EXPECT_NEAR(matches.scores[k], mconf[k].item<float>(), 1e-5);
  }
  // The key image's features serve any number of later frames.
  const auto again = matcher->Match(*f0, *f1);
  EXPECT_EQ(again.points1, matches.points1);
}

TEST(LoftrMatcher, MapsResizedCoordinatesBackToTheOriginalImage) {
  SKIP_WITHOUT_SHARED();
  auto matcher = CreateLoftrMatcher(CoarseOptions());
  const std::string dir = PairDir("labfloor_00100_00130");
  const cv::Mat gray0 = cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat gray1 = cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE);
  cv::Mat big0, big1;
  cv::resize(gray0, big0, cv::Size(1280, 960), 0, 0, cv::INTER_LINEAR);
  cv::resize(gray1, big1, cv::Size(1280, 960), 0, 0, cv::INTER_LINEAR);
  auto f0 = matcher->Extract(big0);
  auto f1 = matcher->Extract(big1);
  EXPECT_EQ(f0->image_size(), cv::Size(1280, 960));
  EXPECT_EQ(f0->num_features(), 30 * 40);  // resized to 640x480 for the network
  const auto matches = matcher->Match(*f0, *f1);
  ASSERT_GT(matches.size(), 100u);
  // Cell corners at 1/16 of 640x480 come back as multiples of 32 in the 1280x960 image.
  for (size_t k = 0; k < matches.size(); ++k) {
    EXPECT_EQ(std::fmod(matches.points0[k].x, 32.f), 0.f);
    EXPECT_EQ(std::fmod(matches.points1[k].y, 32.f), 0.f);
    EXPECT_LT(matches.points0[k].x, 1280.f);
    EXPECT_LT(matches.points0[k].y, 960.f);
  }
}

TEST(LoftrMatcher, NetworkSizeIsMultipleOfStride) {
  SKIP_WITHOUT_SHARED();
  // The KITTI frames (370x1226) go in at 640x192, as the reference preprocessing does.
  auto matcher = CreateLoftrMatcher(CoarseOptions());
  auto features = matcher->Extract(cv::Mat(370, 1226, CV_8UC1, cv::Scalar(90)));
  EXPECT_EQ(features->num_features(), (192 / 16) * (640 / 16));
}

TEST(LoftrMatcher, ExtractsConcurrentlyWithMatching) {
  SKIP_WITHOUT_SHARED();
  auto matcher = CreateLoftrMatcher(CoarseOptions());
  const std::string dir = PairDir("rccar_000000_000006");
  const cv::Mat gray0 = cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat gray1 = cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE);
  auto f0 = matcher->Extract(gray0);
  auto f1 = matcher->Extract(gray1);
  const auto expected = matcher->Match(*f0, *f1);
  std::shared_ptr<const ImageFeatures> prefetched;
  std::thread prefetch([&] {
    for (int i = 0; i < 5; ++i) prefetched = matcher->Extract(gray1);
  });
  for (int i = 0; i < 5; ++i) EXPECT_EQ(matcher->Match(*f0, *f1).points1, expected.points1);
  prefetch.join();
  EXPECT_EQ(matcher->Match(*f0, *prefetched).points1, expected.points1);
}

TEST(LoftrMatcher, NoMatchesIsAnEmptyResultNotACrash) {
  SKIP_WITHOUT_SHARED();
  for (const std::string model : {"coarse", "outdoor"}) {
    LoftrMatcherOptions options = CoarseOptions();
    if (model == "outdoor") {
      options.model = "outdoor";
      options.weights = SharedDir() + "/golden/loftr_full_random/weights_fp16.pt";
      options.longest_side = 128;
    }
    auto matcher = CreateLoftrMatcher(options);
    const cv::Mat flat(96, 128, CV_8UC1, cv::Scalar(128));  // uniform: every confidence equal, below 0.2
    const auto matches = matcher->Match(*matcher->Extract(flat), *matcher->Extract(flat));
    EXPECT_EQ(matches.size(), 0u) << model;
    EXPECT_TRUE(matches.scores.empty());
  }
}

TEST(LoftrMatcher, BadInputGivesInputErrors) {
  SKIP_WITHOUT_SHARED();
  auto matcher = CreateLoftrMatcher(CoarseOptions());
  EXPECT_THROW(matcher->Extract(cv::Mat(12, 200, CV_8UC1, cv::Scalar(0))), InputError);   // < one 16 px cell
  EXPECT_THROW(matcher->Extract(cv::Mat(20, 5000, CV_8UC1, cv::Scalar(0))), InputError);  // rounds to 0 rows
  EXPECT_THROW(matcher->Extract(cv::Mat(64, 64, CV_8UC3, cv::Scalar(0))), InputError);
  LoftrMatcherOptions wrong = CoarseOptions();
  wrong.model = "outdoor";  // the student's file for the full model
  try {
    CreateLoftrMatcher(wrong);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--loftr-model coarse"), std::string::npos) << e.what();
  }
  LoftrMatcherOptions missing = CoarseOptions();
  missing.weights = "/nonexistent/loftr.ckpt";
  EXPECT_THROW(CreateLoftrMatcher(missing), InputError);
}

TEST(LoftrMatcher, CudaWithoutCudaIsAClearError) {
  SKIP_WITHOUT_SHARED();
  if (torch::cuda::is_available()) GTEST_SKIP() << "CUDA is available here";
  LoftrMatcherOptions options = CoarseOptions();
  options.device = "cuda";
  try {
    CreateLoftrMatcher(options);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find("device cuda: "), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("use cpu"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vmap
