// XFeat against the upstream reference outputs in ../shared/golden/xfeat, stage by stage, with the tolerances
// golden/README.md ("xfeat") derives from the reference's own 1-vs-2-thread noise. Keypoint order is not
// compared index by index (ranks of near-equal scores swap between runs of the reference itself): keypoints,
// scores and descriptors are compared by position, matches as sets of coordinates.

#include <array>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/features/float_matcher.h"
#include "vmap/neural/xfeat/xfeat_model.h"
#include "vmap/neural/xfeat/xfeat_weights.h"
#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::LoadJson;
using testing::LoadTensorDict;
using testing::SharedDir;
using TensorMap = std::map<std::string, torch::Tensor>;
using Position = std::pair<int64_t, int64_t>;
using MatchCoordinates = std::array<float, 4>;

// The golden's suggested tolerances (golden.json "suggested_tolerances").
constexpr double kM1Atol = 1e-4, kK1Atol = 2e-4, kH1Atol = 1e-5, kHeatmapAtol = 1e-5;
constexpr double kFp16Rtol = 1e-3, kFp16Atol = 1e-4;
constexpr double kScoreAtol = 1e-5, kDescriptorAtol = 2e-5;
constexpr int64_t kTopK = 4096;
constexpr double kDetectionThreshold = 0.05;

// The exact network input of the reference: the BGR PNG as float32 (1, 3, H, W) = uint8 / 255.
torch::Tensor ReadBgrInput(const std::string& png) {
  const cv::Mat bgr = cv::imread(png, cv::IMREAD_COLOR);
  if (bgr.empty()) throw std::runtime_error("cannot read " + png);
  return torch::from_blob(bgr.data, {1, bgr.rows, bgr.cols, 3}, torch::kUInt8)
             .permute({0, 3, 1, 2})
             .to(torch::kFloat32) /
         255;
}

const XfeatModel& SharedModel() {
  static const XfeatModel model = [] {
    const XfeatWeights weights = LoadXfeatWeights(SharedDir() + "/weights/xfeat/xfeat_folded.pt");
    EXPECT_EQ(weights.layout, XfeatLayout::kFolded);
    return XfeatModel(weights.folded, torch::kCPU);
  }();
  return model;
}

// Compares a map with its stored copy: float16 copies with the float16 tolerance, float32 ones with `atol`.
void ExpectMapNear(const torch::Tensor& ours, const torch::Tensor& stored, double atol, const std::string& name) {
  SCOPED_TRACE(name);
  if (stored.scalar_type() == torch::kFloat16) {
    EXPECT_TENSOR_NEAR(ours, stored.to(torch::kFloat32), kFp16Atol, kFp16Rtol);
  } else {
    EXPECT_TENSOR_NEAR(ours, stored, atol, 0.0);
  }
}

torch::Tensor Crop(const torch::Tensor& map, int64_t top, int64_t left, int64_t size) {
  return map.slice(2, top, top + size).slice(3, left, left + size);
}

std::map<Position, int64_t> PositionRows(const torch::Tensor& positions) {
  std::map<Position, int64_t> rows;
  const auto p = positions.to(torch::kInt64).contiguous();
  for (int64_t k = 0; k < p.size(0); ++k) rows[{p[k][0].item<int64_t>(), p[k][1].item<int64_t>()}] = k;
  return rows;
}

std::set<MatchCoordinates> CoordinateSet(const torch::Tensor& points0, const torch::Tensor& points1) {
  std::set<MatchCoordinates> set;
  for (int64_t k = 0; k < points0.size(0); ++k) {
    set.insert({points0[k][0].item<float>(), points0[k][1].item<float>(), points1[k][0].item<float>(),
                points1[k][1].item<float>()});
  }
  return set;
}

size_t SymmetricDifference(const std::set<MatchCoordinates>& a, const std::set<MatchCoordinates>& b) {
  size_t n = 0;
  for (const auto& m : a) n += !b.count(m);
  for (const auto& m : b) n += !a.count(m);
  return n;
}

// The reference's 1-vs-2-thread noise leaves match sets identical; the smallest best-vs-second margin of a
// stored match is 5.4e-7, so a port with other rounding may flip "a handful" (golden.json).
constexpr size_t kMaxDifferentMatches = 2;

class XfeatGolden : public ::testing::TestWithParam<std::string> {};

TEST_P(XfeatGolden, EveryStageMatchesTheReference) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = SharedDir() + "/golden/xfeat/" + GetParam();
  const TensorMap g = LoadTensorDict(dir + "/golden.pt");
  const auto meta = LoadJson(dir + "/golden.json");
  ASSERT_EQ(meta["config"]["top_k"].get<int64_t>(), kTopK);
  ASSERT_DOUBLE_EQ(meta["config"]["detection_threshold"].get<double>(), kDetectionThreshold);

  XfeatDetectOptions options;
  options.top_k = kTopK;
  options.detection_threshold = kDetectionThreshold;
  options.keep_intermediates = true;
  std::array<XfeatDetections, 2> found;
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE("image " + std::to_string(k));
    const std::string s = std::to_string(k);
    const auto image = ReadBgrInput(dir + "/input" + s + ".png");
    const auto& size = meta["images"]["network_input_hw"];
    found[k] = SharedModel().DetectAndCompute(image, options);
    const XfeatDetections& d = found[k];
    ASSERT_EQ(d.net_height, size[0].get<int64_t>());
    ASSERT_EQ(d.net_width, size[1].get<int64_t>());
    if (g.count("x_net_crop_tl" + s)) {  // resized input (KITTI): corners of the bilinear resize
      EXPECT_TENSOR_NEAR(d.net_input.slice(2, 0, 32).slice(3, 0, 128), g.at("x_net_crop_tl" + s), 1e-6, 0.0);
      EXPECT_TENSOR_NEAR(d.net_input.slice(2, d.net_height - 32).slice(3, d.net_width - 128), g.at("x_net_crop_br" + s),
                         1e-6, 0.0);
    }

    // Network outputs: full maps, and the exact float32 crops where the full map is stored as float16.
    ExpectMapNear(d.net.descriptor_map, g.at("M1_" + s), kM1Atol, "M1");
    ExpectMapNear(d.net.keypoint_logits, g.at("K1_" + s), kK1Atol, "K1");
    ExpectMapNear(d.net.reliability, g.at("H1_" + s), kH1Atol, "H1");
    const int64_t h = d.net.descriptor_map.size(2), w = d.net.descriptor_map.size(3);
    if (g.count("M1_crop_tl" + s)) {
      EXPECT_TENSOR_NEAR(Crop(d.net.descriptor_map, 0, 0, 16), g.at("M1_crop_tl" + s), kM1Atol, 0.0);
      EXPECT_TENSOR_NEAR(Crop(d.net.descriptor_map, h / 2 - 8, w / 2 - 8, 16), g.at("M1_crop_c" + s), kM1Atol, 0.0);
      EXPECT_TENSOR_NEAR(Crop(d.net.keypoint_logits, 0, 0, 16), g.at("K1_crop_tl" + s), kK1Atol, 0.0);
      EXPECT_TENSOR_NEAR(Crop(d.net.keypoint_logits, h / 2 - 8, w / 2 - 8, 16), g.at("K1_crop_c" + s), kK1Atol, 0.0);
    }
    if (g.count("heatmap" + s)) ExpectMapNear(d.heatmap, g.at("heatmap" + s), kHeatmapAtol, "heatmap");
    EXPECT_TENSOR_NEAR(Crop(d.heatmap, 0, 0, 64), g.at("heatmap_crop_tl" + s), kHeatmapAtol, 0.0);
    EXPECT_TENSOR_NEAR(Crop(d.heatmap, d.net_height / 2 - 32, d.net_width / 2 - 32, 64), g.at("heatmap_crop_c" + s),
                       kHeatmapAtol, 0.0);

    // NMS: exactly the same points, in the same (row-major) order; then their scores.
    ASSERT_TRUE(torch::equal(d.nms_keypoints, g.at("nms_keypoints" + s)))
        << d.nms_keypoints.size(0) << " NMS points vs " << g.at("nms_keypoints" + s).size(0);
    EXPECT_TENSOR_NEAR(d.nms_scores, g.at("nms_scores" + s), kScoreAtol, 0.0);

    // Top-k as sets of positions; scores, descriptors and scaled keypoints compared position by position.
    const auto ours = PositionRows(d.nms_keypoints.index_select(0, d.topk_idx));
    const auto theirs = PositionRows(g.at("nms_keypoints" + s).index_select(0, g.at("topk_idx" + s)));
    ASSERT_EQ(d.keypoints.size(0), static_cast<int64_t>(ours.size()));
    ASSERT_EQ(g.at("keypoints" + s).size(0), static_cast<int64_t>(theirs.size()));
    std::vector<int64_t> our_rows, their_rows;
    for (const auto& [position, row] : ours) {
      if (const auto it = theirs.find(position); it != theirs.end()) {
        our_rows.push_back(row);
        their_rows.push_back(it->second);
      }
    }
    EXPECT_GE(our_rows.size(), theirs.size() - 2) << "keypoints in common with the reference";
    const auto ours_index = torch::tensor(our_rows), theirs_index = torch::tensor(their_rows);
    EXPECT_TENSOR_NEAR(d.keypoints.index_select(0, ours_index), g.at("keypoints" + s).index_select(0, theirs_index),
                       0.0, 0.0);
    EXPECT_TENSOR_NEAR(d.scores.index_select(0, ours_index), g.at("scores" + s).index_select(0, theirs_index),
                       kScoreAtol, 0.0);
    EXPECT_TENSOR_NEAR(d.descriptors.index_select(0, ours_index), g.at("descriptors" + s).index_select(0, theirs_index),
                       kDescriptorAtol, 0.0);
    EXPECT_TRUE(torch::allclose(d.descriptors.norm(2, 1), torch::ones({d.descriptors.size(0)}), 0, 1e-6));
  }

  // Matches, at upstream's two settings, as sets of coordinates: through upstream's tensor matcher and
  // through vmap's float matcher (the one the CPU matcher uses).
  for (const auto& [suffix, min_cossim] : {std::pair<std::string, double>{"_mnn0p82", 0.82}, {"_mnn", -1.0}}) {
    SCOPED_TRACE("matches" + suffix);
    const auto reference = CoordinateSet(g.at("mkpts0" + suffix), g.at("mkpts1" + suffix));
    ASSERT_EQ(reference.size(), meta["counts"]["matches" + suffix].get<size_t>());
    const auto [pairs, similarity] = XfeatMatch(found[0].descriptors, found[1].descriptors, min_cossim);
    const auto tensor_matches = CoordinateSet(found[0].keypoints.index_select(0, pairs.select(1, 0)),
                                              found[1].keypoints.index_select(0, pairs.select(1, 1)));
    EXPECT_LE(SymmetricDifference(tensor_matches, reference), kMaxDifferentMatches)
        << tensor_matches.size() << " matches, reference " << reference.size();

    const cv::Mat rows0(static_cast<int>(found[0].descriptors.size(0)), 64, CV_32F, found[0].descriptors.data_ptr());
    const cv::Mat rows1(static_cast<int>(found[1].descriptors.size(0)), 64, CV_32F, found[1].descriptors.data_ptr());
    const float threshold =
        min_cossim > 0 ? std::nextafter(static_cast<float>(min_cossim), 2.f) : -std::numeric_limits<float>::infinity();
    std::vector<int64_t> index0, index1;
    for (const FloatMatch& m : MatchFloatDescriptors(rows0, rows1, threshold)) {
      index0.push_back(m.query);
      index1.push_back(m.train);
    }
    const auto float_matches = CoordinateSet(found[0].keypoints.index_select(0, torch::tensor(index0)),
                                             found[1].keypoints.index_select(0, torch::tensor(index1)));
    EXPECT_LE(SymmetricDifference(float_matches, reference), kMaxDifferentMatches)
        << float_matches.size() << " matches, reference " << reference.size();
  }
}

// The CPU's network (oneDNN's blocked layout, OpenCV's filter2D) against upstream's LibTorch ops, which the
// other devices use: within the golden's float32 tolerances.
TEST(XfeatModel, CpuNetworkEqualsUpstreamsOps) {
  SKIP_WITHOUT_SHARED();
  for (const std::string pair : {"rccar_000000_000006", "kitti07_000010_000014"}) {
    SCOPED_TRACE(pair);
    const auto image = ReadBgrInput(SharedDir() + "/golden/xfeat/" + pair + "/input0.png");
    const auto size = std::vector<int64_t>{image.size(2) / 32 * 32, image.size(3) / 32 * 32};
    const auto input = torch::upsample_bilinear2d(image, size, false);
    const auto fast = SharedModel().Forward(input);
    const auto reference = SharedModel().Forward(input, /*reference_ops=*/true);
    EXPECT_TENSOR_NEAR(fast.descriptor_map, reference.descriptor_map, kM1Atol, 0.0);
    EXPECT_TENSOR_NEAR(fast.keypoint_logits, reference.keypoint_logits, kK1Atol, 0.0);
    EXPECT_TENSOR_NEAR(fast.reliability, reference.reliability, kH1Atol, 0.0);
  }
}

// The CPU's NMS (OpenCV dilation) and descriptor sampling (point by point) against upstream's LibTorch ops:
// on the same network output, the same points, and descriptors equal up to float rounding. KITTI's size
// exercises the resize and the padding of the bicubic taps at the map's border.
TEST(XfeatModel, CpuPostprocessingEqualsUpstreamsOps) {
  SKIP_WITHOUT_SHARED();
  for (const std::string pair : {"rccar_000000_000006", "kitti07_000010_000014"}) {
    SCOPED_TRACE(pair);
    const auto image = ReadBgrInput(SharedDir() + "/golden/xfeat/" + pair + "/input1.png");
    XfeatDetectOptions options;
    options.keep_intermediates = true;
    options.top_k = 100000;  // every NMS point, those at the borders included
    const auto fast = SharedModel().DetectAndCompute(image, options);
    options.upstream_postprocessing_ops = true;
    const auto reference = SharedModel().DetectAndCompute(image, options);
    ASSERT_TRUE(torch::equal(fast.nms_keypoints, reference.nms_keypoints));
    ASSERT_TRUE(torch::equal(fast.topk_idx, reference.topk_idx));
    ASSERT_TRUE(torch::equal(fast.keypoints, reference.keypoints));
    // LibTorch's vectorised kernel groups the products differently: measured at most 1.4e-6 apart, against
    // the golden's 2e-5 tolerance for descriptors.
    EXPECT_TENSOR_NEAR(fast.descriptors, reference.descriptors, 3e-6, 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(AllPairs, XfeatGolden,
                         ::testing::Values("rccar_000000_000006", "labfloor_00100_00130", "kitti07_000010_000014"));

}  // namespace
}  // namespace vmap::neural
