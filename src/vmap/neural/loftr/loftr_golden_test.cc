// The port against the upstream reference outputs in ../shared/golden, with the tolerances that
// golden/README.md derives from the reference's own 1-vs-2-thread noise.

#include <filesystem>
#include <set>

#include <gtest/gtest.h>

#include "vmap/neural/loftr/loftr_model.h"
#include "vmap/neural/loftr/loftr_weights.h"
#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::LoadJson;
using testing::LoadTensorDict;
using testing::ReadNetworkInput;
using testing::SharedDir;
using TensorMap = std::map<std::string, torch::Tensor>;

constexpr double kFeatureAtol = 1e-4, kFeatureRtol = 1e-4;
constexpr double kStudentConfAtol = 1e-5;
// Tensors the golden stores as float16 carry up to half an fp16 ulp (2^-11 relative) of rounding.
constexpr double kFp16Rtol = 1.0 / 2048.0;

// The reference's dual softmax recomputed from its own stored transformer outputs (README: bit-exact with
// the stored conf_matrix), for the pairs whose full matrix was trimmed from the shared copy.
torch::Tensor ReferenceConf(const torch::Tensor& feat0, const torch::Tensor& feat1, double temperature) {
  const double scale = std::sqrt(static_cast<double>(feat0.size(2)));
  auto sim = torch::matmul(feat0 / scale, (feat1 / scale).transpose(1, 2)) / temperature;
  return torch::softmax(sim, 1) * torch::softmax(sim, 2);
}

void ExpectSameMatches(const LoftrPairOutput& out, const TensorMap& g, const std::string& suffix, double conf_atol) {
  ASSERT_TRUE(g.count("i_ids" + suffix)) << suffix;
  EXPECT_TRUE(torch::equal(out.i_ids.cpu(), g.at("i_ids" + suffix)))
      << "i_ids" << suffix << ": " << out.i_ids.size(0) << " vs " << g.at("i_ids" + suffix).size(0);
  EXPECT_TRUE(torch::equal(out.j_ids.cpu(), g.at("j_ids" + suffix))) << "j_ids" << suffix;
  if (out.i_ids.size(0) != g.at("i_ids" + suffix).size(0)) return;
  EXPECT_TENSOR_NEAR(out.mconf, g.at("mconf" + suffix), conf_atol, 0.0);
  EXPECT_TENSOR_NEAR(out.mkpts0_c, g.at("mkpts0_c" + suffix), 0.0, 0.0);
  EXPECT_TENSOR_NEAR(out.mkpts1_c, g.at("mkpts1_c" + suffix), 0.0, 0.0);
}

// ---------------------------------------------------------------- coarse student, real weights

class CoarseStudentGolden : public ::testing::TestWithParam<std::string> {};

TEST_P(CoarseStudentGolden, MatchesReference) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = SharedDir() + "/golden/loftr_coarse/" + GetParam();
  const TensorMap g = LoadTensorDict(dir + "/golden.pt");
  const auto meta = LoadJson(dir + "/golden.json");

  const std::string weights_path = SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt";
  auto weights = ReadStateDict(weights_path);
  LoftrConfig config = LoftrPreset("coarse");
  CheckStateDict(weights, config, weights_path);
  ASSERT_EQ(config.border_removal, meta["thresholds"]["border_rm"].get<int>());
  ASSERT_DOUBLE_EQ(config.threshold, meta["thresholds"]["thr"].get<double>());
  ASSERT_DOUBLE_EQ(config.temperature, meta["config"]["match_coarse"]["dsmax_temperature"].get<double>());
  ASSERT_DOUBLE_EQ(config.layer_norm_eps, meta["layernorm_eps"].get<double>());
  ASSERT_EQ(config.d_model, meta["config"]["coarse"]["d_model"].get<int>());
  LoftrModel model(config, weights, torch::kCPU);

  auto image0 = ReadNetworkInput(dir + "/input0.png");
  auto image1 = ReadNetworkInput(dir + "/input1.png");
  ASSERT_TRUE(torch::equal(image0, g.at("image0").to(torch::kFloat32) / 255.0));
  auto f0 = model.Extract(image0);
  auto f1 = model.Extract(image1);
  EXPECT_TENSOR_NEAR(f0.coarse_backbone, g.at("feat_c0_backbone"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(f1.coarse_backbone, g.at("feat_c1_backbone"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(f0.coarse, g.at("feat_c0_pe"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(f1.coarse, g.at("feat_c1_pe"), kFeatureAtol, kFeatureRtol);

  auto out = model.Match(f0, f1, /*keep_conf=*/true);
  EXPECT_TENSOR_NEAR(out.feat_c0, g.at("feat_c0"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(out.feat_c1, g.at("feat_c1"), kFeatureAtol, kFeatureRtol);
  const torch::Tensor reference_conf =
      g.count("conf_matrix") ? g.at("conf_matrix") : ReferenceConf(g.at("feat_c0"), g.at("feat_c1"), 0.1);
  EXPECT_TENSOR_NEAR(out.conf, reference_conf, kStudentConfAtol, 0.0);
  ExpectSameMatches(out, g, "", kStudentConfAtol);

  // The same network at the other thresholds: the stored 0.1 set where there is one, and the counts that
  // golden.json records for every pair.
  for (const auto& [thr_text, count] : meta["match_counts"].items()) {
    model.set_threshold(std::stod(thr_text));
    auto at_thr = model.Match(f0, f1);
    EXPECT_EQ(at_thr.i_ids.size(0), count.get<int64_t>()) << "threshold " << thr_text;
    if (thr_text == "0.1" && g.count("i_ids_thr0p1")) ExpectSameMatches(at_thr, g, "_thr0p1", kStudentConfAtol);
  }
}

INSTANTIATE_TEST_SUITE_P(AllPairs, CoarseStudentGolden,
                         ::testing::Values("rccar_000000_000006", "rccar_000100_000125", "labfloor_00100_00130",
                                           "kitti07_000010_000014"));

// ---------------------------------------------------------------- full outdoor architecture, random weights

// Rows where the argmax differs are accepted only when the two candidates tie within `atol` in our matrix.
void ExpectArgmaxConsistent(const torch::Tensor& conf, const torch::Tensor& ours, const torch::Tensor& theirs, int dim,
                            double atol) {
  auto differ = ours.cpu().ne(theirs.cpu().flatten()).nonzero().flatten();
  for (int64_t k = 0; k < differ.size(0); ++k) {
    const int64_t idx = differ[k].item<int64_t>();
    const int64_t a = ours[idx].item<int64_t>(), b = theirs.flatten()[idx].item<int64_t>();
    const double va = dim == 1 ? conf[idx][a].item<double>() : conf[a][idx].item<double>();
    const double vb = dim == 1 ? conf[idx][b].item<double>() : conf[b][idx].item<double>();
    EXPECT_LE(std::abs(va - vb), atol) << "argmax differs at " << idx << " beyond a tie";
  }
}

void RunFullGolden(const std::string& dir, const std::string& bn_override, bool has_intermediates) {
  const TensorMap g = LoadTensorDict(dir + "/golden.pt");
  const auto meta = LoadJson(dir + "/golden.json");
  const std::string weights_path = SharedDir() + "/golden/loftr_full_random/weights_fp16.pt";
  auto weights = ReadStateDict(weights_path);
  if (!bn_override.empty()) ApplyOverrides(weights, ReadStateDict(bn_override), bn_override);
  LoftrConfig config = LoftrPreset("outdoor");
  CheckStateDict(weights, config, weights_path);
  ASSERT_EQ(config.border_removal, meta["thresholds"]["border_rm"].get<int>());
  LoftrModel model(config, weights, torch::kCPU);
  model.set_threshold(g.at("thr").item<double>());  // random weights: see golden/README.md, "Threshold"

  auto f0 = model.Extract(ReadNetworkInput(dir + "/input0.png"));
  auto f1 = model.Extract(ReadNetworkInput(dir + "/input1.png"));
  if (has_intermediates) {
    EXPECT_TENSOR_NEAR(f0.coarse_backbone, g.at("feat_c0_backbone"), kFeatureAtol, kFp16Rtol + kFeatureRtol);
    EXPECT_TENSOR_NEAR(f1.coarse_backbone, g.at("feat_c1_backbone"), kFeatureAtol, kFp16Rtol + kFeatureRtol);
    using torch::indexing::None;
    using torch::indexing::Slice;
    EXPECT_TENSOR_NEAR(f0.fine.index({Slice(), Slice(0, None, 32)}), g.at("feat_f0_backbone_ch_step32"), kFeatureAtol,
                       kFeatureRtol);
    EXPECT_TENSOR_NEAR(f1.fine.index({Slice(), Slice(0, None, 32)}), g.at("feat_f1_backbone_ch_step32"), kFeatureAtol,
                       kFeatureRtol);
    const int64_t first_rows = g.at("feat_c0_pe_first2rows").size(1);
    EXPECT_TENSOR_NEAR(f0.coarse.index({Slice(), Slice(0, first_rows)}), g.at("feat_c0_pe_first2rows"), kFeatureAtol,
                       kFeatureRtol);
    EXPECT_TENSOR_NEAR(f1.coarse.index({Slice(), Slice(0, first_rows)}), g.at("feat_c1_pe_first2rows"), kFeatureAtol,
                       kFeatureRtol);
  }
  auto out = model.Match(f0, f1, /*keep_conf=*/true);
  // "rtol 1e-3 of the max" for the full model's flat confidences.
  const double conf_atol = 1e-3 * g.at("conf_rowmax").max().item<double>();
  if (has_intermediates) {
    EXPECT_TENSOR_NEAR(out.feat_c0, g.at("feat_c0"), kFeatureAtol, kFp16Rtol + kFeatureRtol);
    EXPECT_TENSOR_NEAR(out.feat_c1, g.at("feat_c1"), kFeatureAtol, kFp16Rtol + kFeatureRtol);
    auto rows = out.conf.index_select(1, g.at("conf_matrix_row_ids"));
    EXPECT_TENSOR_NEAR(rows, g.at("conf_matrix_rows"), conf_atol, kFp16Rtol);
  }
  auto conf = out.conf[0].cpu();
  EXPECT_TENSOR_NEAR(out.conf.index_select(1, g.at("i_ids")), g.at("conf_matrix_rows_at_i_ids"), conf_atol, 0.0);
  EXPECT_TENSOR_NEAR(out.row_max, g.at("conf_rowmax")[0], conf_atol, 0.0);
  EXPECT_TENSOR_NEAR(out.col_max, g.at("conf_colmax")[0], conf_atol, 0.0);
  ExpectArgmaxConsistent(conf, out.row_argmax, g.at("conf_rowargmax"), 1, conf_atol);
  ExpectArgmaxConsistent(conf, out.col_argmax, g.at("conf_colargmax"), 0, conf_atol);
  ExpectSameMatches(out, g, "", conf_atol);
  if (out.i_ids.size(0) != g.at("i_ids").size(0)) return;

  EXPECT_TENSOR_NEAR(out.fine_pre0, g.at("feat_f0_unfold_pre"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(out.fine_pre1, g.at("feat_f1_unfold_pre"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(out.fine0, g.at("feat_f0_unfold"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(out.fine1, g.at("feat_f1_unfold"), kFeatureAtol, kFeatureRtol);
  EXPECT_TENSOR_NEAR(out.expec_f, g.at("expec_f"), 2e-3, 0.0);
  EXPECT_TENSOR_NEAR(out.mkpts0_f, g.at("mkpts0_f"), 1e-2, 0.0);
  EXPECT_TENSOR_NEAR(out.mkpts1_f, g.at("mkpts1_f"), 1e-2, 0.0);
}

TEST(FullOutdoorGolden, RandomWeightsRccar) {
  SKIP_WITHOUT_SHARED();
  RunFullGolden(SharedDir() + "/golden/loftr_full_random/rccar_000000_000006", "", true);
}

TEST(FullOutdoorGolden, RandomBatchNormStatisticsRccar) {
  SKIP_WITHOUT_SHARED();
  const std::string root = SharedDir() + "/golden/loftr_full_random/extra_bnstats";
  RunFullGolden(root + "/rccar_000000_000006", root + "/bn_override_fp16.pt", false);
}

// Border removal (2 cells outdoor, none indoor) only drops matches whose cell touches the border band.
TEST(LoftrBorderRemoval, DropsExactlyTheBorderBand) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = SharedDir() + "/golden/loftr_full_random/rccar_000000_000006";
  auto weights = ReadStateDict(SharedDir() + "/golden/loftr_full_random/weights_fp16.pt");
  auto small = [&](const std::string& png) {
    return torch::upsample_bilinear2d(ReadNetworkInput(png), {240, 320}, false);
  };
  LoftrConfig with_border = LoftrPreset("outdoor");
  LoftrConfig without_border = with_border;
  without_border.border_removal = LoftrPreset("indoor").border_removal;
  ASSERT_EQ(without_border.border_removal, 0);
  LoftrModel model(with_border, weights, torch::kCPU), open_model(without_border, weights, torch::kCPU);
  model.set_threshold(0.0);
  open_model.set_threshold(0.0);
  auto f0 = model.Extract(small(dir + "/input0.png")), f1 = model.Extract(small(dir + "/input1.png"));
  auto inner = model.Match(f0, f1), all = open_model.Match(f0, f1);
  ASSERT_GT(inner.i_ids.size(0), 0);
  ASSERT_GT(all.i_ids.size(0), inner.i_ids.size(0));
  const int64_t h = f0.coarse_h, w = f0.coarse_w, b = with_border.border_removal;
  auto in_band = [&](int64_t id) {
    const int64_t y = id / w, x = id % w;
    return y < b || y >= h - b || x < b || x >= w - b;
  };
  std::set<std::pair<int64_t, int64_t>> kept;
  for (int64_t k = 0; k < inner.i_ids.size(0); ++k)
    kept.insert({inner.i_ids[k].item<int64_t>(), inner.j_ids[k].item<int64_t>()});
  size_t outside_band = 0;
  for (int64_t k = 0; k < all.i_ids.size(0); ++k) {
    const int64_t i = all.i_ids[k].item<int64_t>(), j = all.j_ids[k].item<int64_t>();
    const bool inside = !in_band(i) && !in_band(j);
    outside_band += inside;
    EXPECT_EQ(kept.count({i, j}) == 1, inside) << i << " -> " << j;
  }
  EXPECT_EQ(outside_band, kept.size());
}

// Every architecture value of the outdoor and indoor presets against the reference configs.
TEST(LoftrPresets, EqualReferenceConfigs) {
  SKIP_WITHOUT_SHARED();
  const auto configs = LoadJson(SharedDir() + "/golden/loftr_full_random/config.json");
  for (const std::string name : {"outdoor", "indoor"}) {
    const auto& ref = configs[name == "outdoor" ? "outdoor_ds" : "indoor_ds_new"]["loftr_config"];
    const LoftrConfig c = LoftrPreset(name);
    SCOPED_TRACE(name);
    EXPECT_EQ(c.backbone, BackboneKind::kResNetFpn8_2);
    EXPECT_EQ(ref["resolution"][0].get<int>(), c.coarse_stride);
    EXPECT_EQ(ref["resolution"][1].get<int>(), c.fine_stride);
    EXPECT_EQ(ref["resnetfpn"]["initial_dim"].get<int>(), c.initial_dim);
    EXPECT_EQ(ref["resnetfpn"]["block_dims"].get<std::vector<int>>(), c.block_dims);
    EXPECT_EQ(ref["coarse"]["d_model"].get<int>(), c.d_model);
    EXPECT_EQ(ref["coarse"]["nhead"].get<int>(), c.nhead);
    EXPECT_EQ(ref["coarse"]["layer_names"].size(), static_cast<size_t>(2 * c.num_coarse_layer_pairs));
    EXPECT_EQ(ref["coarse"]["temp_bug_fix"].get<bool>(), c.temp_bug_fix);
    EXPECT_EQ(ref["match_coarse"]["thr"].get<double>(), c.threshold);
    EXPECT_EQ(ref["match_coarse"]["border_rm"].get<int>(), c.border_removal);
    EXPECT_EQ(ref["match_coarse"]["dsmax_temperature"].get<double>(), c.temperature);
    EXPECT_EQ(ref["match_coarse"]["match_type"].get<std::string>(), "dual_softmax");
    EXPECT_EQ(ref["fine_window_size"].get<int>(), c.fine_window);
    EXPECT_EQ(ref["fine_concat_coarse_feat"].get<bool>(), c.fine_concat_coarse_feat);
    EXPECT_EQ(ref["fine"]["d_model"].get<int>(), c.fine_d_model);
    EXPECT_EQ(ref["fine"]["nhead"].get<int>(), c.fine_nhead);
    EXPECT_EQ(ref["fine"]["layer_names"].size(), static_cast<size_t>(2 * c.num_fine_layer_pairs));
    EXPECT_EQ(c.layer_norm_eps, 1e-5);
  }
  const auto student = LoadJson(SharedDir() + "/golden/loftr_coarse/rccar_000000_000006/golden.json");
  const LoftrConfig c = LoftrPreset("coarse");
  EXPECT_EQ(student["config"]["resolution"][0].get<int>(), c.coarse_stride);
  EXPECT_EQ(student["config"]["resnetfpn"]["block_dims"].get<std::vector<int>>(), c.block_dims);
  EXPECT_EQ(student["config"]["resnetfpn"]["initial_dim"].get<int>(), c.initial_dim);
  EXPECT_EQ(student["config"]["coarse"]["nhead"].get<int>(), c.nhead);
  EXPECT_EQ(student["config"]["coarse"]["layer_names"].size(), static_cast<size_t>(2 * c.num_coarse_layer_pairs));
  EXPECT_EQ(student["config"]["coarse"]["temp_bug_fix"].get<bool>(), c.temp_bug_fix);
  EXPECT_EQ(student["linear_attention_eps"].get<double>(), c.attention_eps);
  EXPECT_FALSE(c.has_fine);
}

// The positional encoding of both variants against the reference's values at a few positions:
// buggy (outdoor, student) frequencies are exp(-k), fixed ones 10000^(-k/(d/2)).
TEST(PositionalEncoding, MatchesReferenceFirstRows) {
  SKIP_WITHOUT_SHARED();
  const TensorMap g = LoadTensorDict(SharedDir() + "/golden/loftr_coarse/labfloor_00100_00130/golden.pt");
  auto pe = g.at("feat_c0_pe") - g.at("feat_c0_backbone").flatten(2).transpose(1, 2);  // (1, L, 32)
  auto weights = ReadStateDict(SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt");
  LoftrModel model(LoftrPreset("coarse"), weights, torch::kCPU);
  auto ours = model.PositionalEncoding(30, 40).flatten(2).transpose(1, 2);
  EXPECT_TENSOR_NEAR(ours, pe, 1e-5, 0.0);
  // The fixed variant differs (indoor): its first y-sine channel at row 1 is sin(1 * 1) either way,
  // but the second frequency is 10000^(-4/128) instead of e^-1.
  LoftrConfig fixed = LoftrPreset("coarse");
  fixed.temp_bug_fix = true;
  LoftrModel fixed_model(fixed, weights, torch::kCPU);
  auto fixed_pe = fixed_model.PositionalEncoding(1, 1);
  EXPECT_NEAR(fixed_pe[0][4][0][0].item<double>(), std::sin(std::pow(10000.0, -2.0 / 16.0)), 1e-6);
  EXPECT_NEAR(model.PositionalEncoding(1, 1)[0][4][0][0].item<double>(), std::sin(std::exp(-2.0)), 1e-6);
}

}  // namespace
}  // namespace vmap::neural
