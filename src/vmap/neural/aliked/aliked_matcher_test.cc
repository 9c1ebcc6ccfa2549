// The ALIKED matcher through the Matcher interface: reference keypoints and matches, coordinates, options and
// bad input.

#include "vmap/neural/aliked/aliked_matcher.h"

#include <array>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/features/camera_mask.h"
#include "vmap/mapping/pair_match.h"
#include "vmap/testing/golden_util.h"
#include "vmap/testing/masked_extraction.h"

namespace vmap {
namespace {

using neural::testing::ExpectInputError;

using neural::testing::LoadTensorDict;
using neural::testing::SharedDir;

std::string PairDir(const std::string& model, const std::string& pair) {
  return SharedDir() + "/golden/aliked-" + model + "/" + pair;
}

AlikedMatcherOptions Options(const std::string& model) {
  AlikedMatcherOptions options;
  options.model = model;
  options.weights = SharedDir() + "/weights/aliked/aliked-" + model + ".pt";
  return options;
}

// Matches as (x0, y0, x1, y1) rounded to 1e-2 px, for set comparisons independent of keypoint order.
std::set<std::array<long, 4>> AsSet(const std::vector<cv::Point2f>& p0, const std::vector<cv::Point2f>& p1) {
  std::set<std::array<long, 4>> out;
  for (size_t i = 0; i < p0.size(); ++i) {
    out.insert({std::lround(p0[i].x * 100), std::lround(p0[i].y * 100), std::lround(p1[i].x * 100),
                std::lround(p1[i].y * 100)});
  }
  return out;
}

size_t CommonCount(const std::set<std::array<long, 4>>& a, const std::set<std::array<long, 4>>& b) {
  size_t n = 0;
  for (const auto& x : a) n += b.count(x);
  return n;
}

// Upstream's matches at its demo's similarity (0.75), as coordinates.
std::set<std::array<long, 4>> ReferenceMatches(const std::map<std::string, torch::Tensor>& g) {
  std::vector<cv::Point2f> expected0, expected1;
  const auto& index = g.at("matches_mnn0p75");
  for (int64_t i = 0; i < index.size(0); ++i) {
    const int64_t a = index[i][0].item<int64_t>(), b = index[i][1].item<int64_t>();
    expected0.emplace_back(g.at("keypoints_px0")[a][0].item<float>(), g.at("keypoints_px0")[a][1].item<float>());
    expected1.emplace_back(g.at("keypoints_px1")[b][0].item<float>(), g.at("keypoints_px1")[b][1].item<float>());
  }
  return AsSet(expected0, expected1);
}

// Through Extract/Match on the stored grey inputs, with upstream's settings (top-k 1000, similarity 0.75):
// the reference's matches, as coordinates.
TEST(AlikedMatcher, ReproducesTheReferenceMatchesThroughTheInterface) {
  SKIP_WITHOUT_SHARED();
  for (const auto& [model, pair] :
       {std::pair{"t16", "rccar_000000_000006"}, std::pair{"n16", "kitti07_000010_000014"}}) {
    const std::string dir = PairDir(model, pair);
    const auto g = LoadTensorDict(dir + "/golden.pt");
    auto options = Options(model);
    options.top_k = 1000;
    options.min_similarity = 0.75;
    const auto matcher = CreateAlikedMatcher(options);
    const cv::Mat image0 = cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE);
    const cv::Mat image1 = cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE);
    const auto f0 = matcher->Extract(image0);
    const auto f1 = matcher->Extract(image1);
    EXPECT_EQ(f0->num_features(), 1000);
    EXPECT_EQ(f0->image_size(), image0.size());
    const auto matches = matcher->Match(*f0, *f1);

    const auto ours = AsSet(matches.points0, matches.points1);
    const auto reference = ReferenceMatches(g);
    // Keypoints may differ only where the top-k boundary is a near-tie (golden README); allow a handful.
    EXPECT_GE(CommonCount(ours, reference), reference.size() - 3) << model << " " << pair;
    EXPECT_LE(ours.size(), reference.size() + 3);
    for (float s : matches.scores) EXPECT_GE(s, 0.75f);
  }
}

// A colour frame through the product's path (MatchPair gives ExtractFrame the BGR image): upstream's demo
// reads the colour image and gives the network R, G, B; so must vmap, to reproduce its matches.
TEST(AlikedMatcher, ColourImagesGiveTheReferencesMatches) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = PairDir("n16", "labfloor_00100_00130_rgb");
  const auto g = LoadTensorDict(dir + "/golden.pt");
  auto options = Options("n16");
  options.top_k = 1000;
  options.min_similarity = 0.75;
  const auto matcher = CreateAlikedMatcher(options);
  ASSERT_TRUE(matcher->reads_color());
  std::array<PairImage, 2> images{PairImage(cv::Mat()), PairImage(cv::Mat())};
  for (int k = 0; k < 2; ++k) {
    const std::string png = dir + "/input" + std::to_string(k) + ".png";
    images[k] = PairImage(cv::imread(png, cv::IMREAD_GRAYSCALE), cv::imread(png, cv::IMREAD_COLOR));
    ASSERT_EQ(images[k].bgr.type(), CV_8UC3);
  }
  const TentativeMatches matches = MatchPair(*matcher, images[0], images[1], VerifierOptions{}).matches;
  const auto ours = AsSet(matches.points0, matches.points1);
  const auto reference = ReferenceMatches(g);
  EXPECT_GE(CommonCount(ours, reference), reference.size() - 3) << ours.size() << " matches";
  EXPECT_LE(ours.size(), reference.size() + 3);

  // The grey image is another input, with other matches: the test above tells the two paths apart.
  const TentativeMatches from_grey =
      matcher->Match(*matcher->Extract(images[0].gray), *matcher->Extract(images[1].gray));
  EXPECT_LT(CommonCount(AsSet(from_grey.points0, from_grey.points1), reference) + 10, CommonCount(ours, reference));
}

TEST(AlikedMatcher, ExtractsWithinACameraMask) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = PairDir("t16", "rccar_000000_000006");
  // Every peak, so that top_k does not bind: where it does, the mask gives peaks that the whole image's top_k leaves
  // out (KeepsItsTopKWithinACameraMask).
  AlikedMatcherOptions every_peak = Options("t16");
  every_peak.top_k = 100000;
  testing::ExpectFeaturesWithinTheMask(*CreateAlikedMatcher(every_peak),
                                       cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE),
                                       cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE));
}

// Where top_k binds, a camera mask keeps (nearly) the whole budget within it: a peak at the mask's edge that the
// sub-pixel refinement moves out of it is dropped after. Dropping keypoints after detection left about half.
TEST(AlikedMatcher, KeepsItsTopKWithinACameraMask) {
  SKIP_WITHOUT_SHARED();
  const cv::Mat gray = cv::imread(PairDir("t16", "rccar_000000_000006") + "/input0.png", cv::IMREAD_GRAYSCALE);
  cv::Mat keep(gray.size(), CV_8UC1, cv::Scalar(255));
  keep.colRange(0, gray.cols / 2).setTo(0);
  AlikedMatcherOptions options = Options("t16");
  options.top_k = 300;
  const auto matcher = CreateAlikedMatcher(options);
  options.top_k = 100000;
  const auto every = CreateAlikedMatcher(options)->Extract(gray);

  const auto within = matcher->ExtractFrameWithin(gray, cv::Mat(), keep);
  EXPECT_GE(within->num_features(), 290);
  EXPECT_LE(within->num_features(), 300);
  EXPECT_LT(KeptPointIndices(keep, testing::KeypointsOf(*matcher, *matcher->Extract(gray))).size(), 200u);
  // Each a peak found without the mask, with its descriptor there (but for float rounding).
  testing::ExpectEachFoundWithoutTheMask(*matcher, *within, *every, keep, 1e-5);
}

TEST(AlikedMatcher, ShrinkingMapsKeypointsBackToTheOriginalImage) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = PairDir("t16", "rccar_000000_000006");
  const cv::Mat image = cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE);
  cv::Mat doubled;
  cv::resize(image, doubled, image.size() * 2, 0, 0, cv::INTER_LINEAR);
  auto options = Options("t16");
  options.min_similarity = 0.9;
  const auto native = CreateAlikedMatcher(options);
  options.longest_side = 640;
  const auto shrinking = CreateAlikedMatcher(options);
  const auto at_native = native->Extract(image);
  const auto from_doubled = shrinking->Extract(doubled);
  EXPECT_EQ(from_doubled->image_size(), doubled.size());
  // The 1280x960 image is shrunk back to 640x480: its keypoints, mapped to 1280x960 pixel centres, are
  // twice the native ones plus half a pixel.
  const auto matches = native->Match(*at_native, *from_doubled);
  ASSERT_GT(matches.size(), 300u);
  int close = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    const cv::Point2f expected = matches.points0[i] * 2.f + cv::Point2f(0.5f, 0.5f);
    close += cv::norm(matches.points1[i] - expected) < 1.0;
  }
  EXPECT_GT(close, static_cast<int>(matches.size() * 9 / 10));
}

TEST(AlikedMatcher, ThresholdModeAndTopKBothWork) {
  SKIP_WITHOUT_SHARED();
  const auto meta = neural::testing::LoadJson(PairDir("t16", "rccar_000000_000006") + "/golden.json");
  const cv::Mat image = cv::imread(PairDir("t16", "rccar_000000_000006") + "/input0.png", cv::IMREAD_GRAYSCALE);
  auto options = Options("t16");
  options.top_k = 0;  // upstream demo mode: score > 0.2
  const auto thresholded = CreateAlikedMatcher(options)->Extract(image);
  EXPECT_NEAR(thresholded->num_features(), meta["robustness"]["image0"]["n_threshold_mode"].get<int>(), 2);
  options.max_keypoints = 300;
  EXPECT_EQ(CreateAlikedMatcher(options)->Extract(image)->num_features(), 300);
  options.top_k = 200;
  EXPECT_EQ(CreateAlikedMatcher(options)->Extract(image)->num_features(), 200);
}

TEST(AlikedMatcher, ExtractAndMatchRunConcurrently) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = PairDir("t16", "rccar_000000_000006");
  const cv::Mat image0 = cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat image1 = cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE);
  const auto matcher = CreateAlikedMatcher(Options("t16"));
  const auto key = matcher->Extract(image0);
  const size_t expected = matcher->Match(*key, *matcher->Extract(image1)).size();
  std::vector<size_t> counts(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < counts.size(); ++t) {
    threads.emplace_back([&, t] { counts[t] = matcher->Match(*key, *matcher->Extract(image1)).size(); });
  }
  for (auto& thread : threads) thread.join();
  for (size_t count : counts) EXPECT_EQ(count, expected);
}

TEST(AlikedMatcher, BlankSmallAndOddImagesNeverCrash) {
  SKIP_WITHOUT_SHARED();
  const auto matcher = CreateAlikedMatcher(Options("t16"));
  const auto blank = matcher->Extract(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)));
  const auto other = matcher->Extract(cv::Mat(480, 640, CV_8UC1, cv::Scalar(30)));
  const auto matches = matcher->Match(*blank, *other);
  EXPECT_EQ(matches.points0.size(), matches.points1.size());
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(5, 3), cv::Size(33, 70), cv::Size(1226, 370)}) {
    cv::Mat noise(size, CV_8UC1);
    cv::randu(noise, 0, 255);
    const auto features = matcher->Extract(noise);
    EXPECT_EQ(features->image_size(), size);
    const auto self = matcher->Match(*features, *features);
    EXPECT_EQ(self.size(), static_cast<size_t>(features->num_features()));  // every keypoint matches itself
  }
  EXPECT_NE(ExpectInputError([&] { matcher->Extract(cv::Mat(10, 10, CV_8UC3)); }).find("8-bit single-channel"),
            std::string::npos);
}

TEST(AlikedMatcher, RecordsItsOptions) {
  SKIP_WITHOUT_SHARED();
  auto options = Options("n16");
  options.min_similarity = 0.8;
  const auto j = nlohmann::json::parse(CreateAlikedMatcher(options)->DescribeOptionsJson());
  EXPECT_EQ(j["type"], "aliked");
  EXPECT_EQ(j["model"], "aliked-n16");
  EXPECT_EQ(j["weights"], options.weights);
  EXPECT_EQ(j["top_k"], options.top_k);
  EXPECT_DOUBLE_EQ(j["min_similarity"].get<double>(), 0.8);
  EXPECT_EQ(j["device"], "cpu");
}

TEST(AlikedMatcher, BadOptionsAndDevicesAreClearErrors) {
  SKIP_WITHOUT_SHARED();
  auto options = Options("t16");
  options.model = "n32";
  EXPECT_EQ(ExpectInputError([&] { CreateAlikedMatcher(options); }).find("model 'n32' is not an ALIKED model; use t16"),
            0u);
  options = Options("t16");
  options.top_k = -3;
  EXPECT_EQ(ExpectInputError([&] { CreateAlikedMatcher(options); }).find("top_k must be >= 0"), 0u);
  options = Options("t16");
  options.min_similarity = 1.5;
  EXPECT_EQ(ExpectInputError([&] {
              CreateAlikedMatcher(options);
            }).find("min_similarity 1.5 is outside [-1, 1] (default 0.75; a cosine similarity)"),
            0u);
  options = Options("t16");
  options.longest_side = 16;
  EXPECT_EQ(ExpectInputError([&] {
              CreateAlikedMatcher(options);
            }).find("longest_side 16 is not 0 nor at least 32 (default 0; 0: native size)"),
            0u);
  options = Options("t16");
  options.weights = SharedDir() + "/weights/aliked/aliked-n16.pt";  // the other model's file
  EXPECT_NE(ExpectInputError([&] { CreateAlikedMatcher(options); }).find("fits --aliked-model n16"), std::string::npos);
  options = Options("t16");
  options.weights = SharedDir() + "/weights/aliked/no-such-file.pt";
  EXPECT_NE(ExpectInputError([&] { CreateAlikedMatcher(options); }).find("is missing; give the weights file"),
            std::string::npos);
  if (!torch::cuda::is_available()) {
    options = Options("t16");
    options.device = "cuda";
    EXPECT_EQ(ExpectInputError([&] { CreateAlikedMatcher(options); }).find("device cuda: "), 0u);
  }
}

// With a GPU, the CUDA model gives the CPU model's keypoints and matches.
TEST(AlikedMatcher, CudaAgreesWithCpu) {
  SKIP_WITHOUT_SHARED();
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  const std::string dir = PairDir("n16", "rccar_000000_000006");
  const cv::Mat image0 = cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat image1 = cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE);
  auto options = Options("n16");
  const auto cpu = CreateAlikedMatcher(options);
  options.device = "cuda";
  const auto cuda = CreateAlikedMatcher(options);
  const auto on_cpu = cpu->Match(*cpu->Extract(image0), *cpu->Extract(image1));
  const auto on_cuda = cuda->Match(*cuda->Extract(image0), *cuda->Extract(image1));
  const auto a = AsSet(on_cpu.points0, on_cpu.points1), b = AsSet(on_cuda.points0, on_cuda.points1);
  EXPECT_GE(CommonCount(a, b), a.size() * 98 / 100);
}

}  // namespace
}  // namespace vmap
