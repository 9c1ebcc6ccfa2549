// ALIKED weights: the architecture's key set against the shared files, upstream's OrderedDict layout, and bad files.

#include "vmap/neural/aliked/aliked_weights.h"

#include <fstream>

#include <caffe2/serialize/inline_container.h>
#include <gtest/gtest.h>
#include <torch/serialize.h>

#include "vmap/core/error.h"
#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::ExpectInputError;
using testing::WriteBytes;
using testing::WriteOrderedDictFile;

using testing::SharedDir;

std::string WeightsPath(const std::string& model) { return SharedDir() + "/weights/aliked/aliked-" + model + ".pt"; }

TEST(AlikedWeights, SharedFilesHoldExactlyTheExpectedTensors) {
  SKIP_WITHOUT_SHARED();
  for (const std::string model : {"t16", "n16"}) {
    const auto weights = ReadAlikedStateDict(WeightsPath(model));
    const auto expected = AlikedExpectedStateDict(AlikedPreset(model));
    EXPECT_EQ(weights.size(), 76u) << model;
    EXPECT_EQ(expected.size(), 76u) << model;
    CheckAlikedStateDict(weights, AlikedPreset(model), WeightsPath(model));
    EXPECT_EQ(AlikedModelsFitting(weights), std::vector<std::string>{model});
  }
  // Parameter counts of the paper's Table (ALIKED-T16 0.192 M, ALIKED-N16 0.677 M), BatchNorm statistics excluded.
  for (const auto& [model, expected] : {std::pair{"t16", 192}, std::pair{"n16", 677}}) {
    int64_t learnable = 0;
    for (const auto& [key, t] : ReadAlikedStateDict(WeightsPath(model))) {
      if (key.find("running_") == std::string::npos && key.find("num_batches") == std::string::npos) {
        learnable += t.numel();
      }
    }
    EXPECT_EQ((learnable + 500) / 1000, expected) << model << ": " << learnable;
  }
}

TEST(AlikedWeights, ReadsUpstreamOrderedDictFiles) {
  SKIP_WITHOUT_SHARED();
  const testing::ScopedTempDir temp("aliked_weights");
  const auto weights = ReadAlikedStateDict(WeightsPath("t16"));
  const std::string path = temp.path() / "aliked-t16.pth";
  WriteOrderedDictFile(weights, path);
  // LibTorch alone cannot read this layout (it fails on the OrderedDict); the reader falls back to its own
  // unpickler.
  std::ifstream file(path, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_ANY_THROW(torch::pickle_load(bytes));
  const auto loaded = ReadAlikedStateDict(path);
  ASSERT_EQ(loaded.size(), weights.size());
  for (const auto& [key, t] : weights) {
    ASSERT_TRUE(loaded.count(key)) << key;
    EXPECT_TRUE(torch::equal(loaded.at(key), t)) << key;
  }
  CheckAlikedStateDict(loaded, AlikedPreset("t16"), path);
}

TEST(AlikedWeights, ReadsAStateDictNestedUnderStateDict) {
  SKIP_WITHOUT_SHARED();
  const testing::ScopedTempDir temp("aliked_weights");
  const auto weights = ReadAlikedStateDict(WeightsPath("n16"));
  c10::Dict<std::string, torch::Tensor> state;
  for (const auto& [key, t] : weights) state.insert(key, t);
  c10::impl::GenericDict checkpoint(c10::StringType::get(), c10::AnyType::get());
  checkpoint.insert("epoch", c10::IValue(int64_t{3}));
  checkpoint.insert("state_dict", c10::IValue(state));
  const std::string path = temp.path() / "nested.pt";
  WriteBytes(path, torch::pickle_save(c10::IValue(checkpoint)));
  EXPECT_EQ(AlikedModelsFitting(ReadAlikedStateDict(path)), std::vector<std::string>{"n16"});
}

TEST(AlikedWeights, WrongModelListsKeysAndNamesTheRightOne) {
  SKIP_WITHOUT_SHARED();
  const std::string path = WeightsPath("n16");
  const auto weights = ReadAlikedStateDict(path);
  const std::string message = ExpectInputError([&] { CheckAlikedStateDict(weights, AlikedPreset("t16"), path); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("keys with another shape"), std::string::npos) << message;
  EXPECT_NE(message.find("block1.conv1.weight (file float32 16x3x3x3, expected float32 8x3x3x3)"), std::string::npos)
      << message;
  EXPECT_NE(message.find("--aliked-model n16"), std::string::npos) << message;
}

TEST(AlikedWeights, MissingUnexpectedAndChangedKeysAreReported) {
  SKIP_WITHOUT_SHARED();
  const std::string path = WeightsPath("t16");
  auto weights = ReadAlikedStateDict(path);
  weights.erase("desc_head.agg_weights");
  weights["desc_head.convM.weight"] = torch::zeros({64, 1024, 1, 1});         // the conv2D variant of SDDH
  weights["block3.conv1.offset_conv.weight"] = torch::zeros({27, 16, 3, 3});  // a modulated (DCNv2) offset conv
  const std::string message = ExpectInputError([&] { CheckAlikedStateDict(weights, AlikedPreset("t16"), path); });
  EXPECT_NE(message.find("missing keys (1):\n    desc_head.agg_weights"), std::string::npos) << message;
  EXPECT_NE(message.find("unexpected keys (1):\n    desc_head.convM.weight"), std::string::npos) << message;
  EXPECT_NE(message.find("block3.conv1.offset_conv.weight (file float32 27x16x3x3, expected float32 18x16x3x3)"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("fits no ALIKED model"), std::string::npos) << message;
  EXPECT_TRUE(AlikedModelsFitting(weights).empty());
}

TEST(AlikedWeights, TruncatedAndForeignFilesGiveClearErrors) {
  SKIP_WITHOUT_SHARED();
  const testing::ScopedTempDir temp("aliked_weights");
  std::ifstream source(WeightsPath("t16"), std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
  for (size_t keep : {size_t{0}, size_t{100}, bytes.size() / 2, bytes.size() - 10}) {
    const std::string path = temp.path() / ("truncated_" + std::to_string(keep) + ".pt");
    WriteBytes(path, std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep)));
    const std::string message = ExpectInputError([&] { ReadAlikedStateDict(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("ALIKED weights file"), std::string::npos) << message;
  }
  const std::string text_path = temp.path() / "notes.txt";
  WriteBytes(text_path, {'h', 'e', 'l', 'l', 'o'});
  EXPECT_NE(ExpectInputError([&] { ReadAlikedStateDict(text_path); }).find("not a complete torch.save"),
            std::string::npos);
  const std::string list_path = temp.path() / "list.pt";
  WriteBytes(list_path, torch::pickle_save(c10::IValue(c10::List<int64_t>({1, 2}))));
  EXPECT_NE(ExpectInputError([&] { ReadAlikedStateDict(list_path); }).find("not a dict"), std::string::npos);
  EXPECT_NE(ExpectInputError([&] { ReadAlikedStateDict(temp.path() / "absent.pt"); }).find("is missing"),
            std::string::npos);
  // A LoFTR state dict is readable but fits no ALIKED model.
  const auto loftr = ReadAlikedStateDict(SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt");
  EXPECT_TRUE(AlikedModelsFitting(loftr).empty());
}

}  // namespace
}  // namespace vmap::neural
