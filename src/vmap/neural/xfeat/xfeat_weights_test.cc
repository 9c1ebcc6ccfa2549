// XFeat weights: the shared folded file, the official layout users download (BatchNorm statistics and the
// unused fine_matcher, as a plain dict and as the collections.OrderedDict torch.save writes), and bad files.

#include "vmap/neural/xfeat/xfeat_weights.h"

#include <fstream>

#include <caffe2/serialize/inline_container.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <torch/serialize.h>

#include "vmap/core/error.h"
#include "vmap/neural/xfeat/xfeat_model.h"
#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::ExpectInputError;
using testing::WriteBytes;

using testing::SharedDir;

std::string SharedWeights() { return SharedDir() + "/weights/xfeat/xfeat_folded.pt"; }

void SaveDict(const StateDict& weights, const std::string& path) {
  c10::Dict<std::string, torch::Tensor> dict;
  for (const auto& [key, tensor] : weights) dict.insert(key, tensor);
  WriteBytes(path, torch::pickle_save(c10::IValue(dict)));
}

// Rewrites a plain-dict file as torch.save(model.state_dict()) writes it: the top-level dict becomes a
// collections.OrderedDict, which LibTorch's own unpickler cannot return.
void MakeOrderedDict(const std::string& plain, const std::string& ordered) {
  caffe2::serialize::PyTorchStreamReader reader(plain);
  auto [pickle_data, pickle_size] = reader.getRecord("data.pkl");
  std::string program(static_cast<const char*>(pickle_data.get()), pickle_size);
  // LibTorch writes restore_type_tag(<dict>, "Dict[str, Tensor]"); Python writes the bare dict. Unwrap it,
  // then build the dict as collections.OrderedDict() (GLOBAL, EMPTY_TUPLE, REDUCE) instead of EMPTY_DICT.
  const std::string tag(
      "\x80\x02"
      "ctorch.jit._pickle\nrestore_type_tag\nq\x00",
      40);
  const std::string type_name = "Dict[str, Tensor]";
  const size_t type_at = program.rfind(type_name);
  ASSERT_EQ(program.substr(0, tag.size()), tag) << "unexpected pickle from torch::pickle_save";
  ASSERT_NE(type_at, std::string::npos);
  ASSERT_EQ(program[tag.size()], '}');
  program =
      "\x80\x02"
      "ccollections\nOrderedDict\n)R" +
      program.substr(tag.size() + 1, type_at - 5 - tag.size() - 1) + ".";
  caffe2::serialize::PyTorchStreamWriter writer(ordered);
  writer.writeRecord("data.pkl", program.data(), program.size());
  for (const std::string& name : reader.getAllRecords()) {
    if (name == "data.pkl") continue;
    auto [data, size] = reader.getRecord(name);
    writer.writeRecord(name, data.get(), size);
  }
  writer.writeEndOfFile();
}

constexpr double kEps = 1e-5;

// The official layout for the folded weights: seeded random BatchNorm statistics, and conv weights chosen so
// that folding them gives back the folded tensors (up to float32 rounding), plus a fine_matcher.
StateDict OfficialLayoutOf(const StateDict& folded) {
  torch::manual_seed(5);
  StateDict official;
  for (const XfeatConv& conv : XfeatConvolutions()) {
    if (!conv.batch_norm) {
      official[conv.weight_key()] = folded.at(conv.weight_key());
      official[conv.bias_key()] = folded.at(conv.bias_key());
      continue;
    }
    const auto var = torch::rand({conv.out_channels}, torch::kFloat64).mul(3.0).add(0.05);
    const auto std = var.add(kEps).sqrt();
    const std::string bn = conv.name + ".layer.1.";
    official[conv.weight_key()] =
        folded.at(conv.weight_key()).to(torch::kFloat64).mul(std.view({-1, 1, 1, 1})).to(torch::kFloat32);
    official[bn + "running_mean"] = folded.at(conv.bias_key()).to(torch::kFloat64).neg().mul(std).to(torch::kFloat32);
    official[bn + "running_var"] = var.to(torch::kFloat32);
    official[bn + "num_batches_tracked"] = torch::tensor(int64_t{160000});
  }
  // XFeat*'s refinement MLP (Linear + BatchNorm1d); the sparse pipeline never reads it.
  official["fine_matcher.0.weight"] = torch::randn({512, 128});
  official["fine_matcher.0.bias"] = torch::randn({512});
  official["fine_matcher.1.running_mean"] = torch::randn({512});
  official["fine_matcher.1.running_var"] = torch::rand({512});
  official["fine_matcher.1.num_batches_tracked"] = torch::tensor(int64_t{160000});
  official["fine_matcher.12.weight"] = torch::randn({64, 512});
  official["fine_matcher.12.bias"] = torch::randn({64});
  return official;
}

TEST(XfeatWeights, SharedFileIsTheFoldedLayout) {
  SKIP_WITHOUT_SHARED();
  const StateDict weights = ReadXfeatStateDict(SharedWeights());
  EXPECT_EQ(weights.size(), 54u);
  int64_t numbers = 0;
  for (const auto& [key, tensor] : weights) numbers += tensor.numel();
  EXPECT_EQ(numbers, 659282);  // ../shared/weights/xfeat/README.md
  EXPECT_EQ(CheckXfeatStateDict(weights, SharedWeights()), XfeatLayout::kFolded);
  const XfeatWeights loaded = LoadXfeatWeights(SharedWeights());
  for (const auto& [key, tensor] : weights) EXPECT_TRUE(torch::equal(loaded.folded.at(key), tensor)) << key;
}

TEST(XfeatWeights, FoldingIsLibTorchsBatchNorm) {
  // A BasicLayer's conv with random statistics: conv + BatchNorm2d(affine=False) in LibTorch against the
  // folded conv.
  torch::manual_seed(3);
  const auto weight = torch::randn({64, 64, 3, 3}) * 0.1;
  const auto mean = torch::randn({64});
  const auto var = torch::rand({64}) * 2;
  const auto [folded_weight, folded_bias] = FoldBatchNorm(weight, mean, var);
  const auto x = torch::randn({1, 64, 24, 32});
  const auto expected =
      torch::batch_norm(torch::conv2d(x, weight, {}, 1, 1), {}, {}, mean, var, false, 0.0, kEps, false);
  const auto actual = torch::conv2d(x, folded_weight, folded_bias, 1, 1);
  EXPECT_TENSOR_NEAR(actual, expected, 2e-5, 1e-5);
}

TEST(XfeatWeights, OfficialLayoutLoadsAsPlainAndOrderedDictAndGivesTheSameNetwork) {
  SKIP_WITHOUT_SHARED();
  const testing::ScopedTempDir dir("xfeat_weights");
  const StateDict folded = ReadXfeatStateDict(SharedWeights());
  const StateDict official = OfficialLayoutOf(folded);
  SaveDict(official, dir.path() / "plain.pt");
  MakeOrderedDict(dir.path() / "plain.pt", dir.path() / "xfeat.pt");
  // LibTorch alone cannot read the OrderedDict file: this exercises vmap's own reader.
  {
    std::ifstream file(dir.path() / "xfeat.pt", std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    bool libtorch_reads_a_dict = false;
    try {
      libtorch_reads_a_dict = torch::pickle_load(bytes).isGenericDict();
    } catch (const std::exception&) {
    }
    EXPECT_FALSE(libtorch_reads_a_dict);
  }
  for (const std::string name : {"plain.pt", "xfeat.pt"}) {
    SCOPED_TRACE(name);
    const StateDict read = ReadXfeatStateDict(dir.path() / name);
    ASSERT_EQ(read.size(), official.size());
    for (const auto& [key, tensor] : official) ASSERT_TRUE(torch::equal(read.at(key), tensor)) << key;
    const XfeatWeights loaded = LoadXfeatWeights(dir.path() / name);
    EXPECT_EQ(loaded.layout, XfeatLayout::kOfficial);
    ASSERT_EQ(loaded.folded.size(), 54u);
    for (const auto& [key, tensor] : folded) EXPECT_TENSOR_NEAR(loaded.folded.at(key), tensor, 1e-7, 1e-6);
  }

  // The network with both: the same outputs within the golden's float32 tolerances, the same keypoints.
  const XfeatModel reference(folded, torch::kCPU);
  const XfeatModel from_official(LoadXfeatWeights(dir.path() / "xfeat.pt").folded, torch::kCPU);
  const auto image = testing::ReadNetworkInput(SharedDir() + "/golden/xfeat/labfloor_00100_00130/input0.png");
  XfeatDetectOptions options;
  options.keep_intermediates = true;
  const auto a = reference.DetectAndCompute(image, options);
  const auto b = from_official.DetectAndCompute(image, options);
  EXPECT_TENSOR_NEAR(b.net.descriptor_map, a.net.descriptor_map, 1e-4, 0.0);
  EXPECT_TENSOR_NEAR(b.net.keypoint_logits, a.net.keypoint_logits, 2e-4, 0.0);
  EXPECT_TENSOR_NEAR(b.net.reliability, a.net.reliability, 1e-5, 0.0);
  ASSERT_TRUE(torch::equal(b.nms_keypoints, a.nms_keypoints));
  EXPECT_TENSOR_NEAR(b.nms_scores, a.nms_scores, 1e-5, 0.0);
}

TEST(XfeatWeights, MissingUnexpectedAndMisshapedKeysAreListed) {
  SKIP_WITHOUT_SHARED();
  const StateDict folded = ReadXfeatStateDict(SharedWeights());
  StateDict broken = folded;
  broken.erase("block3.1.layer.0.bias");
  broken["extra.weight"] = torch::zeros({3});
  broken["block1.0.layer.0.weight"] = torch::zeros({4, 1, 5, 5});
  std::string message = ExpectInputError([&] { CheckXfeatStateDict(broken, "broken.pt"); });
  for (const std::string expected :
       {"'broken.pt'", "folded layout", "missing keys (1)", "block3.1.layer.0.bias", "unexpected keys (1)",
        "extra.weight", "block1.0.layer.0.weight (file float32 4x1x5x5, expected float32 4x1x3x3)"}) {
    EXPECT_NE(message.find(expected), std::string::npos) << expected << " not in: " << message;
  }

  StateDict official = OfficialLayoutOf(folded);
  official.erase("block5.2.layer.1.running_var");
  official["block5.2.layer.1.num_batches_tracked"] = torch::zeros({1});
  message = ExpectInputError([&] { CheckXfeatStateDict(official, "xfeat.pt"); });
  for (const std::string expected : {"official layout", "block5.2.layer.1.running_var",
                                     "block5.2.layer.1.num_batches_tracked (file float32 1, expected int64 scalar)"}) {
    EXPECT_NE(message.find(expected), std::string::npos) << expected << " not in: " << message;
  }

  official = OfficialLayoutOf(folded);
  official["block2.0.layer.1.running_var"][3] = -1.0f;
  EXPECT_NE(ExpectInputError([&] { CheckXfeatStateDict(official, "xfeat.pt"); }).find("negative"), std::string::npos);

  const std::string loftr = SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt";
  message = ExpectInputError([&] { LoadXfeatWeights(loftr); });
  EXPECT_NE(message.find("fits no XFeat layout"), std::string::npos) << message;
  EXPECT_NE(message.find(loftr), std::string::npos) << message;
}

TEST(XfeatWeights, TruncatedAndForeignFilesNameTheFile) {
  SKIP_WITHOUT_SHARED();
  const testing::ScopedTempDir dir("xfeat_weights");
  std::ifstream source(SharedWeights(), std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
  for (size_t keep : {size_t{0}, size_t{100}, bytes.size() / 2, bytes.size() - 10}) {
    const std::string path = dir.path() / ("truncated_" + std::to_string(keep) + ".pt");
    WriteBytes(path, std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep)));
    const std::string message = ExpectInputError([&] { LoadXfeatWeights(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("not a complete torch.save"), std::string::npos) << message;
  }
  WriteBytes(dir.path() / "list.pt", torch::pickle_save(c10::IValue(c10::List<int64_t>({1, 2}))));
  EXPECT_NE(ExpectInputError([&] { LoadXfeatWeights(dir.path() / "list.pt"); }).find("not a dict"), std::string::npos);
  EXPECT_NE(ExpectInputError([&] { LoadXfeatWeights(dir.path() / "absent.pt"); }).find("is missing"),
            std::string::npos);
}

}  // namespace
}  // namespace vmap::neural
