// XFeat behind the Matcher interface: the reference through Extract/Match on grey images, coordinates in
// the image given, options recorded, concurrent use, and bad input.

#include "vmap/neural/xfeat/xfeat_matcher.h"

#include <array>
#include <map>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/features/camera_mask.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/mapping/pair_match.h"
#include "vmap/testing/golden_util.h"
#include "vmap/testing/masked_extraction.h"

namespace vmap {
namespace {

using neural::testing::ExpectInputError;

using neural::testing::LoadTensorDict;
using neural::testing::SharedDir;

XfeatMatcherOptions SharedOptions() {
  XfeatMatcherOptions options;
  options.weights = SharedDir() + "/weights/xfeat/xfeat_folded.pt";
  options.top_k = 4096;
  options.min_similarity = 0.82;
  return options;
}

std::string PairDir(const std::string& pair) { return SharedDir() + "/golden/xfeat/" + pair; }

TEST(XfeatMatcher, ReproducesTheReferenceThroughTheInterface) {
  SKIP_WITHOUT_SHARED();
  // KITTI is grey (B = G = R in the stored PNGs), so the grey image the interface takes is the reference's
  // input; the image is resized from 1226x370 to 1216x352 and the keypoints come back in 1226x370 pixels.
  MatcherOptions options;
  options.type = "xfeat";
  options.Of<XfeatMatcherOptions>() = SharedOptions();
  const auto matcher = CreateMatcher(options);
  EXPECT_EQ(matcher->name(), "xfeat");
  const std::string dir = PairDir("kitti07_000010_000014");
  const auto f0 = matcher->Extract(cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE));
  const auto f1 = matcher->Extract(cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE));
  EXPECT_EQ(f0->image_size(), cv::Size(1226, 370));
  EXPECT_EQ(f0->num_features(), 4096);
  const TentativeMatches matches = matcher->Match(*f0, *f1);
  const auto g = LoadTensorDict(dir + "/golden.pt");
  const auto mkpts0 = g.at("mkpts0_mnn0p82"), mkpts1 = g.at("mkpts1_mnn0p82"), cossim = g.at("cossim_mnn0p82");
  std::map<std::array<float, 4>, float> reference;
  for (int64_t k = 0; k < mkpts0.size(0); ++k) {
    reference[{mkpts0[k][0].item<float>(), mkpts0[k][1].item<float>(), mkpts1[k][0].item<float>(),
               mkpts1[k][1].item<float>()}] = cossim[k].item<float>();
  }
  ASSERT_EQ(matches.scores.size(), matches.size());
  size_t common = 0;
  for (size_t k = 0; k < matches.size(); ++k) {
    const auto it =
        reference.find({matches.points0[k].x, matches.points0[k].y, matches.points1[k].x, matches.points1[k].y});
    if (it == reference.end()) continue;
    ++common;
    EXPECT_NEAR(matches.scores[k], it->second, 2e-5);
    EXPECT_GT(matches.scores[k], 0.82f);
  }
  EXPECT_GE(common + 2, reference.size()) << matches.size() << " matches";
  EXPECT_LE(matches.size(), common + 2);
  // The key image's features serve any number of later frames.
  EXPECT_EQ(matcher->Match(*f0, *f1).points1, matches.points1);
}

// Colour pairs through the path `vmap match` takes (MatchPair with the decoded grey and BGR images): the
// network sees the mean of B, G and R as upstream's, so the reference's matches come back, up to the handful
// golden/README.md allows. The decoder's luminance grey alone reproduced about 55 % of them.
TEST(XfeatMatcher, ColourImagesGiveTheReferencesMatches) {
  SKIP_WITHOUT_SHARED();
  MatcherOptions options;
  options.type = "xfeat";
  options.Of<XfeatMatcherOptions>() = SharedOptions();
  const auto matcher = CreateMatcher(options);
  ASSERT_TRUE(matcher->reads_color());
  for (const std::string pair : {"rccar_000000_000006", "labfloor_00100_00130"}) {
    SCOPED_TRACE(pair);
    const std::string dir = PairDir(pair);
    std::array<PairImage, 2> images{PairImage(cv::Mat()), PairImage(cv::Mat())};
    for (int k = 0; k < 2; ++k) {
      const std::string png = dir + "/input" + std::to_string(k) + ".png";
      images[k] = PairImage(cv::imread(png, cv::IMREAD_GRAYSCALE), cv::imread(png, cv::IMREAD_COLOR));
      ASSERT_EQ(images[k].bgr.type(), CV_8UC3);
    }
    const PairMatch result = MatchPair(*matcher, images[0], images[1], VerifierOptions{});
    const auto g = LoadTensorDict(dir + "/golden.pt");
    const auto mkpts0 = g.at("mkpts0_mnn0p82"), mkpts1 = g.at("mkpts1_mnn0p82");
    std::set<std::array<float, 4>> reference;
    for (int64_t k = 0; k < mkpts0.size(0); ++k) {
      reference.insert({mkpts0[k][0].item<float>(), mkpts0[k][1].item<float>(), mkpts1[k][0].item<float>(),
                        mkpts1[k][1].item<float>()});
    }
    const TentativeMatches& matches = result.matches;
    size_t common = 0;
    for (size_t k = 0; k < matches.size(); ++k) {
      common +=
          reference.count({matches.points0[k].x, matches.points0[k].y, matches.points1[k].x, matches.points1[k].y});
    }
    EXPECT_GE(common + 2, reference.size()) << common << " of the reference's " << reference.size() << " matches";
    EXPECT_LE(matches.size(), common + 2) << matches.size() << " matches";
  }
}

// A grey frame (no colour image) is the grey image itself, whatever the matcher.
TEST(XfeatMatcher, FrameWithoutColourIsItsGreyImage) {
  SKIP_WITHOUT_SHARED();
  const auto matcher = CreateXfeatMatcher(SharedOptions());
  const cv::Mat gray = cv::imread(PairDir("rccar_000000_000006") + "/input0.png", cv::IMREAD_GRAYSCALE);
  const auto from_gray = matcher->Extract(gray);
  const auto from_frame = matcher->ExtractFrame(gray, cv::Mat());
  ASSERT_EQ(from_frame->num_features(), from_gray->num_features());
  EXPECT_EQ(cv::norm(from_frame->descriptors(), from_gray->descriptors(), cv::NORM_INF), 0.0);
  EXPECT_NE(ExpectInputError([&] { matcher->ExtractFrame(gray, gray); }).find("8-bit BGR"), std::string::npos);
}

TEST(XfeatMatcher, ExtractsWithinACameraMask) {
  SKIP_WITHOUT_SHARED();
  // Every peak, so that top_k does not bind: where it does, the mask gives peaks that the whole image's top_k leaves
  // out (KeepsItsTopKWithinACameraMask).
  XfeatMatcherOptions options = SharedOptions();
  options.top_k = 100000;
  const auto matcher = CreateXfeatMatcher(options);
  const std::string dir = PairDir("rccar_000000_000006");
  testing::ExpectFeaturesWithinTheMask(*matcher, cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE),
                                       cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE));
}

// Where top_k binds (a KITTI frame has thousands of peaks), a camera mask keeps the whole budget within it: the top_k
// best peaks inside the mask, where dropping the keypoints after detection left about half of top_k.
TEST(XfeatMatcher, KeepsItsTopKWithinACameraMask) {
  SKIP_WITHOUT_SHARED();
  const cv::Mat gray = cv::imread(PairDir("kitti07_000010_000014") + "/input0.png", cv::IMREAD_GRAYSCALE);
  cv::Mat keep(gray.size(), CV_8UC1, cv::Scalar(255));
  keep.colRange(0, gray.cols / 2).setTo(0);
  XfeatMatcherOptions options = SharedOptions();
  options.top_k = 300;
  const auto matcher = CreateXfeatMatcher(options);
  options.top_k = 100000;  // every peak, best first
  const auto every = CreateXfeatMatcher(options)->Extract(gray);

  const auto within = matcher->ExtractFrameWithin(gray, cv::Mat(), keep);
  ASSERT_EQ(within->num_features(), 300);
  EXPECT_LT(KeptPointIndices(keep, testing::KeypointsOf(*matcher, *matcher->Extract(gray))).size(), 200u);
  // The 300 best of the peaks inside the mask, each with the descriptor it has without a mask.
  const std::vector<int> inside = KeptPointIndices(keep, testing::KeypointsOf(*matcher, *every));
  ASSERT_GT(inside.size(), 300u);
  const std::set<int> best(inside.begin(), inside.begin() + 300);
  for (int found : testing::ExpectEachFoundWithoutTheMask(*matcher, *within, *every, keep, 0.0)) {
    EXPECT_EQ(best.count(found), 1u) << "peak " << found << " is not among the best inside the mask";
  }
}

TEST(XfeatMatcher, OptionsShapeTheOutputAndAreRecorded) {
  SKIP_WITHOUT_SHARED();
  XfeatMatcherOptions options = SharedOptions();
  options.top_k = 500;
  options.min_similarity = 0.9;
  const auto matcher = CreateXfeatMatcher(options);
  const std::string dir = PairDir("rccar_000000_000006");
  const auto f0 = matcher->Extract(cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE));
  const auto f1 = matcher->Extract(cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE));
  EXPECT_EQ(f0->num_features(), 500);
  const auto matches = matcher->Match(*f0, *f1);
  ASSERT_GT(matches.size(), 100u);
  for (float s : matches.scores) EXPECT_GT(s, 0.9f);
  const auto json = nlohmann::json::parse(matcher->DescribeOptionsJson());
  EXPECT_EQ(json["type"], "xfeat");
  EXPECT_EQ(json["top_k"], 500);
  EXPECT_EQ(json["min_similarity"], 0.9);
  EXPECT_EQ(json["detection_threshold"], 0.05);
  EXPECT_EQ(json["weights_layout"], "folded");
  EXPECT_EQ(json["device"], "cpu");
  EXPECT_EQ(json["weights"], options.weights);
}

TEST(XfeatMatcher, ConcurrentExtractAndMatchGiveTheSameResults) {
  SKIP_WITHOUT_SHARED();
  XfeatMatcherOptions options = SharedOptions();
  options.top_k = 1000;
  const auto matcher = CreateXfeatMatcher(options);
  const std::string dir = PairDir("labfloor_00100_00130");
  const cv::Mat gray0 = cv::imread(dir + "/input0.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat gray1 = cv::imread(dir + "/input1.png", cv::IMREAD_GRAYSCALE);
  const auto f0 = matcher->Extract(gray0);
  const auto f1 = matcher->Extract(gray1);
  const auto expected = matcher->Match(*f0, *f1);
  std::vector<TentativeMatches> results(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < results.size(); ++t) {
    threads.emplace_back([&, t] {
      const auto a = matcher->Extract(t % 2 ? gray1 : gray0);
      const auto b = matcher->Extract(t % 2 ? gray0 : gray1);
      results[t] = t % 2 ? matcher->Match(*b, *a) : matcher->Match(*a, *b);
    });
  }
  for (auto& thread : threads) thread.join();
  for (const auto& r : results) {
    EXPECT_EQ(r.points0, expected.points0);
    EXPECT_EQ(r.points1, expected.points1);
  }
}

TEST(XfeatMatcher, BadInputIsRefusedClearly) {
  SKIP_WITHOUT_SHARED();
  const auto matcher = CreateXfeatMatcher(SharedOptions());
  EXPECT_NE(ExpectInputError([&] { matcher->Extract(cv::Mat(64, 64, CV_8UC3, cv::Scalar(0))); }).find("single-channel"),
            std::string::npos);
  EXPECT_NE(ExpectInputError([&] { matcher->Extract(cv::Mat(31, 64, CV_8UC1, cv::Scalar(0))); }).find("32x32"),
            std::string::npos);
  // A blank image has no keypoints, and matching it gives nothing.
  const auto blank = matcher->Extract(cv::Mat(96, 128, CV_8UC1, cv::Scalar(128)));
  EXPECT_EQ(blank->num_features(), 0);
  EXPECT_EQ(matcher->Match(*blank, *blank).size(), 0u);

  XfeatMatcherOptions cuda = SharedOptions();
  cuda.device = "cuda";
  if (!torch::cuda::is_available()) {
    EXPECT_EQ(ExpectInputError([&] { CreateXfeatMatcher(cuda); }).find("device cuda: "), 0u);
  }
  XfeatMatcherOptions bad = SharedOptions();
  bad.top_k = 0;
  // Named by the JSON keys of the fields.
  EXPECT_EQ(ExpectInputError([&] { bad.Check(); }).find("top_k 0 is less than 1"), 0u);
  bad = SharedOptions();
  bad.min_similarity = 1.5;
  EXPECT_EQ(ExpectInputError([&] { bad.Check(); }).find("min_similarity 1.5 is outside [-1, 1)"), 0u);
  bad = SharedOptions();
  bad.detection_threshold = -0.1;
  EXPECT_EQ(ExpectInputError([&] { bad.Check(); }).find("detection_threshold -0.1 is outside [0, 1)"), 0u);
  bad = SharedOptions();
  bad.device = "tpu";
  EXPECT_EQ(ExpectInputError([&] { bad.Check(); }).find("device 'tpu' is not a device"), 0u);
  bad = SharedOptions();
  bad.weights = SharedDir() + "/no/such/file.pt";
  EXPECT_NE(ExpectInputError([&] { CreateXfeatMatcher(bad); }).find("is missing; give the weights file"),
            std::string::npos);
}

}  // namespace
}  // namespace vmap
