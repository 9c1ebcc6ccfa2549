// ALIKED against the upstream reference outputs in ../shared/golden/aliked-{t16,n16}, with the tolerances of
// golden/README.md (score map 1e-5, descriptors 1e-4, keypoints 1e-3 px; match sets exactly equal).

#include <map>
#include <ostream>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/features/float_matcher.h"
#include "vmap/neural/aliked/aliked_model.h"
#include "vmap/neural/aliked/aliked_weights.h"
#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::LoadJson;
using testing::LoadTensorDict;
using testing::SharedDir;
using TensorMap = std::map<std::string, torch::Tensor>;

constexpr double kScoreMapAtol = 1e-5;
constexpr double kDescriptorAtol = 1e-4;
constexpr double kKeypointPxAtol = 1e-3;
// Scores sampled at our own keypoints also carry their sub-pixel position noise; the reference's own 1-vs-2
// thread difference is 1.9e-5 (golden README).
constexpr double kKeypointScoreAtol = 5e-5;
// SDDH offsets are not in the README's list; they are linear in the features (|offset| up to ~100 px), so
// a descriptor-level 1e-4 relative noise allows ~1e-3 px.
constexpr double kOffsetAtol = 2e-3;

// The network input the golden used: gray3 pairs as one grey channel (the model treats it as three), rgb
// pairs as imread(COLOR) -> BGR2RGB.
torch::Tensor ReadInput(const std::string& png, bool rgb) {
  cv::Mat image = cv::imread(png, rgb ? cv::IMREAD_COLOR : cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error("cannot read " + png);
  if (rgb) cv::cvtColor(image, image, cv::COLOR_BGR2RGB);
  auto bytes = torch::from_blob(image.data, {1, image.rows, image.cols, image.channels()}, torch::kUInt8)
                   .permute({0, 3, 1, 2})
                   .clone(torch::MemoryFormat::Contiguous);  // owns its pixels: `image` is freed on return
  return bytes;
}

torch::Tensor ToNetwork(const torch::Tensor& bytes) { return bytes.to(torch::kFloat32) / 255.0; }

// Upstream's demo matcher, verbatim in behaviour: similarities below th are zeroed, then argmax both ways
// and mutual check. A row with nothing >= th argmaxes to column 0 (its quirk).
torch::Tensor UpstreamDemoMatches(const torch::Tensor& d0, const torch::Tensor& d1, double th) {
  auto sim = d0.matmul(d1.t());
  sim.masked_fill_(sim < th, 0.0);
  auto nn12 = sim.argmax(1), nn21 = sim.argmax(0);
  auto ids1 = torch::arange(d0.size(0), torch::kLong);
  auto mask = ids1 == nn21.index_select(0, nn12);
  return torch::stack({ids1.index({mask}), nn12.index({mask})}, 1);
}

torch::Tensor AsTensor(const std::vector<FloatMatch>& matches) {
  auto out = torch::empty({static_cast<int64_t>(matches.size()), 2}, torch::kLong);
  for (size_t i = 0; i < matches.size(); ++i) {
    out[i][0] = matches[i].query;
    out[i][1] = matches[i].train;
  }
  return out;
}

cv::Mat AsMat(const torch::Tensor& rows) {
  auto c = rows.to(torch::kCPU).to(torch::kFloat32).contiguous();
  return cv::Mat(static_cast<int>(c.size(0)), static_cast<int>(c.size(1)), CV_32F, c.data_ptr<float>()).clone();
}

torch::Tensor ToPixels(const torch::Tensor& normalised, int64_t height, int64_t width) {
  auto wh = torch::tensor({float(width - 1), float(height - 1)});
  return (normalised.to(torch::kCPU) + 1) / 2 * wh;
}

// For each golden keypoint, the index of ours at the same position (within kKeypointPxAtol), or -1.
std::vector<int64_t> MatchByPosition(const torch::Tensor& ours_px, const torch::Tensor& golden_px) {
  auto distance = torch::cdist(golden_px.to(torch::kFloat64), ours_px.to(torch::kFloat64));
  auto [best, index] = distance.min(1);
  std::vector<int64_t> out(golden_px.size(0), -1);
  for (int64_t i = 0; i < golden_px.size(0); ++i) {
    if (best[i].item<double>() <= kKeypointPxAtol) out[i] = index[i].item<int64_t>();
  }
  return out;
}

struct GoldenPair {
  std::string model;  // "t16" / "n16"
  std::string pair;
};

// Without this GoogleTest prints the parameter as raw bytes into every test's name in ctest.
void PrintTo(const GoldenPair& golden, std::ostream* out) { *out << golden.model << "/" << golden.pair; }

std::string PairName(const ::testing::TestParamInfo<GoldenPair>& info) {
  std::string name = info.param.model + "_" + info.param.pair;
  for (auto& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

class AlikedGolden : public ::testing::TestWithParam<GoldenPair> {
 protected:
  void SetUp() override {
    if (!testing::SharedDataPresent()) GTEST_SKIP() << "no shared data at " << SharedDir() << "/golden";
    dir_ = SharedDir() + "/golden/aliked-" + GetParam().model + "/" + GetParam().pair;
    g_ = LoadTensorDict(dir_ + "/golden.pt");
    meta_ = LoadJson(dir_ + "/golden.json");
    const std::string weights_path = SharedDir() + "/weights/aliked/aliked-" + GetParam().model + ".pt";
    config_ = AlikedPreset(GetParam().model);
    auto weights = ReadAlikedStateDict(weights_path);
    CheckAlikedStateDict(weights, config_, weights_path);
    model_ = std::make_unique<AlikedModel>(config_, weights, torch::kCPU);
    rgb_ = meta_["input_mode"] == "rgb";
  }

  DkdOptions GoldenDkd() const {
    DkdOptions options;
    options.top_k = meta_["config"]["top_k"].get<int>();
    options.radius = meta_["config"]["radius"].get<int>();
    options.temperature = meta_["config"]["dkd_temperature"].get<double>();
    options.sub_pixel = meta_["config"]["sub_pixel"].get<bool>();
    options.drop_suppressed = false;  // upstream keeps whatever top-k returns
    return options;
  }

  std::string dir_;
  TensorMap g_;
  nlohmann::json meta_;
  AlikedConfig config_;
  std::unique_ptr<AlikedModel> model_;
  bool rgb_ = false;
};

TEST_P(AlikedGolden, ConfigurationIsTheReferenceOne) {
  const auto& arch = meta_["config"]["arch"];
  EXPECT_EQ(config_.c1, arch["c1"].get<int>());
  EXPECT_EQ(config_.c2, arch["c2"].get<int>());
  EXPECT_EQ(config_.c3, arch["c3"].get<int>());
  EXPECT_EQ(config_.c4, arch["c4"].get<int>());
  EXPECT_EQ(config_.dim, arch["dim"].get<int>());
  EXPECT_EQ(config_.kernel, arch["K"].get<int>());
  EXPECT_EQ(config_.num_samples, arch["M"].get<int>());
  const DkdOptions defaults;
  EXPECT_EQ(defaults.radius, meta_["config"]["radius"].get<int>());
  EXPECT_EQ(defaults.top_k, meta_["config"]["top_k"].get<int>());
  EXPECT_DOUBLE_EQ(defaults.temperature, meta_["config"]["dkd_temperature"].get<double>());
  EXPECT_DOUBLE_EQ(defaults.score_threshold, meta_["config"]["scores_th_threshold_mode"].get<double>());
  EXPECT_EQ(defaults.max_keypoints, meta_["config"]["n_limit_threshold_mode"].get<int>());
}

// DKD alone, on the reference's own score map: the same keypoints in the same order.
TEST_P(AlikedGolden, DkdOnTheReferenceScoreMapIsExact) {
  torch::InferenceMode guard;
  for (int k = 0; k < 2; ++k) {
    const std::string s = std::to_string(k);
    const auto& score_map = g_.at("score_map" + s);
    const auto result = DetectKeypoints(score_map, GoldenDkd());
    ASSERT_EQ(result.keypoints.sizes(), g_.at("keypoints" + s).sizes());
    EXPECT_TENSOR_NEAR(result.keypoints, g_.at("keypoints" + s), 1e-6, 0.0);
    EXPECT_TENSOR_NEAR(ToPixels(result.keypoints, score_map.size(2), score_map.size(3)), g_.at("keypoints_px" + s),
                       1e-4, 0.0);
    // Scores go through a softmax: LibTorch's vectorised exp differs between its AVX2 and AVX-512 kernels by
    // up to 3.5e-6 here (measured), while the positions above stay exact.
    EXPECT_TENSOR_NEAR(result.scores, g_.at("kptscores" + s), 1e-5, 0.0);
    EXPECT_TENSOR_NEAR(result.dispersity, g_.at("scoredispersity" + s), 1e-5, 0.0);

    // Threshold mode (the upstream demos'): the stored count.
    DkdOptions threshold_mode = GoldenDkd();
    threshold_mode.top_k = -1;
    const auto thresholded = DetectKeypoints(score_map, threshold_mode);
    EXPECT_EQ(thresholded.keypoints.size(0), meta_["robustness"]["image" + s]["n_threshold_mode"].get<int64_t>());
    EXPECT_GT(thresholded.scores.min().item<float>(), 0.0f);
  }
}

TEST_P(AlikedGolden, ScoreMapKeypointsAndDescriptorsMatchTheReference) {
  torch::InferenceMode guard;
  AlikedDescriptors descriptors[2];
  for (int k = 0; k < 2; ++k) {
    const std::string s = std::to_string(k);
    const auto bytes = ReadInput(dir_ + "/input" + s + ".png", rgb_);
    ASSERT_TRUE(torch::equal(bytes, g_.at("image" + s))) << "input" << s << ".png differs from the stored tensor";
    const auto maps = model_->ExtractDenseMaps(ToNetwork(bytes));
    EXPECT_TENSOR_NEAR(maps.score_map, g_.at("score_map" + s), kScoreMapAtol, 0.0);

    // Our own detections, compared as sets by position (ties in the top-k may legitimately reorder).
    const auto detected = DetectKeypoints(maps.score_map, GoldenDkd());
    const int64_t height = maps.height, width = maps.width;
    const auto ours_px = ToPixels(detected.keypoints, height, width);
    const auto& golden_px = g_.at("keypoints_px" + s);
    const auto correspondence = MatchByPosition(ours_px, golden_px);
    int64_t common = 0;
    for (auto index : correspondence) common += index >= 0;
    EXPECT_GE(common, golden_px.size(0) - 2) << "image " << k << ": keypoints in common with the reference";

    // Descriptors at the reference keypoints: index-aligned with the stored ones.
    descriptors[k] = model_->Describe(maps, g_.at("keypoints" + s));
    EXPECT_TENSOR_NEAR(descriptors[k].descriptors, g_.at("descriptors" + s), kDescriptorAtol, 0.0);
    EXPECT_TENSOR_NEAR(descriptors[k].offsets, g_.at("sddh_offsets" + s), kOffsetAtol, 0.0);

    // Descriptors at our own keypoints, where they coincide with the reference's.
    const auto own = model_->Describe(maps, detected.keypoints).descriptors;
    std::vector<int64_t> ours_index, golden_index;
    for (size_t i = 0; i < correspondence.size(); ++i) {
      if (correspondence[i] >= 0) golden_index.push_back(int64_t(i)), ours_index.push_back(correspondence[i]);
    }
    EXPECT_TENSOR_NEAR(own.index_select(0, torch::tensor(ours_index)),
                       g_.at("descriptors" + s).index_select(0, torch::tensor(golden_index)), kDescriptorAtol, 0.0);
    EXPECT_TENSOR_NEAR(detected.scores.index_select(0, torch::tensor(ours_index)),
                       g_.at("kptscores" + s).index_select(0, torch::tensor(golden_index)), kKeypointScoreAtol, 0.0);
  }

  // Matching: upstream's demo rule and vmap's mutual-nearest-neighbour matcher give the stored match sets, on the
  // reference descriptors and on ours.
  for (const auto& [suffix, threshold] : {std::pair{"0p75", 0.75}, std::pair{"0p9", 0.9}}) {
    const auto& expected = g_.at(std::string("matches_mnn") + suffix);
    ASSERT_EQ(meta_["counts"][std::string("mnn") + suffix + "_below_th_quirk"].get<int>(), 0);
    EXPECT_TRUE(torch::equal(UpstreamDemoMatches(g_.at("descriptors0"), g_.at("descriptors1"), threshold), expected));
    const auto on_reference = MatchFloatDescriptors(AsMat(g_.at("descriptors0")), AsMat(g_.at("descriptors1")),
                                                    static_cast<float>(threshold));
    EXPECT_TRUE(torch::equal(AsTensor(on_reference), expected)) << suffix;
    const auto on_ours = MatchFloatDescriptors(AsMat(descriptors[0].descriptors), AsMat(descriptors[1].descriptors),
                                               static_cast<float>(threshold));
    EXPECT_TRUE(torch::equal(AsTensor(on_ours), expected))
        << suffix << ": " << on_ours.size() << " matches vs " << expected.size(0);
    ASSERT_EQ(on_ours.size(), static_cast<size_t>(expected.size(0)));
    for (size_t i = 0; i < on_ours.size(); ++i) {
      EXPECT_NEAR(on_ours[i].similarity, g_.at(std::string("matches_mnn") + suffix + "_sim")[i].item<float>(), 1e-4);
    }
  }
}

// The descriptor head reads the feature map only where it needs it; that equals the full map (up to the
// rounding of the upsampling weights, which LibTorch's kernel computes in another order: ~2e-6 here).
TEST_P(AlikedGolden, SparseFeatureReadsEqualTheDenseFeatureMap) {
  torch::InferenceMode guard;
  const auto maps = model_->ExtractDenseMaps(ToNetwork(ReadInput(dir_ + "/input0.png", rgb_)));
  const auto dense = model_->DenseFeatureMap(maps);
  ASSERT_EQ(dense.sizes(), (std::vector<int64_t>{1, config_.dim, maps.height, maps.width}));
  torch::manual_seed(3);
  auto rows = torch::randint(maps.height, {500}, torch::kLong);
  auto cols = torch::randint(maps.width, {500}, torch::kLong);
  // Corners and edges too.
  rows = torch::cat({rows, torch::tensor({int64_t{0}, int64_t{0}, maps.height - 1, maps.height - 1})});
  cols = torch::cat({cols, torch::tensor({int64_t{0}, maps.width - 1, int64_t{0}, maps.width - 1})});
  const auto sparse = model_->FeaturesAt(maps, rows, cols);
  const auto expected = dense[0].index({torch::indexing::Slice(), rows, cols}).t();
  EXPECT_TENSOR_NEAR(sparse, expected, 1e-5, 0.0);
}

// The CPU NMS loop against the tensor formulation (max_pool2d), on maps with plateaus of equal scores, where
// upstream's recovery rounds matter.
TEST(AlikedDkd, CpuNmsEqualsTheTensorFormulation) {
  torch::manual_seed(11);
  for (const auto& size : {std::pair{37, 53}, std::pair{4, 3}, std::pair{1, 9}, std::pair{120, 160}}) {
    for (double levels : {4.0, 16.0, 1e6}) {
      const auto map = (torch::rand({1, 1, size.first, size.second}) * levels).floor() / levels;
      const auto cpu = SimpleNms(map, 2);                                                // float: the loop
      const auto reference = SimpleNms(map.to(torch::kFloat64), 2).to(torch::kFloat32);  // max_pool2d
      EXPECT_TRUE(torch::equal(cpu, reference)) << size.first << "x" << size.second << " levels " << levels;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Pairs, AlikedGolden,
                         ::testing::Values(GoldenPair{"t16", "rccar_000000_000006"},
                                           GoldenPair{"n16", "rccar_000000_000006"},
                                           GoldenPair{"n16", "kitti07_000010_000014"},
                                           GoldenPair{"n16", "labfloor_00100_00130_rgb"}),
                         PairName);

}  // namespace
}  // namespace vmap::neural
