// Reading weights files in every layout torch.save gives them, and comparing a state dict with a network's.

#include "vmap/neural/state_dict.h"

#include <filesystem>

#include <gtest/gtest.h>
#include <torch/serialize.h>

#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::ExpectInputError;
using testing::ScopedTempDir;
using testing::WriteBytes;

StateDict SmallStateDict() {
  torch::manual_seed(7);
  return {{"conv.weight", torch::randn({4, 3, 3, 3})},
          {"conv.bias", torch::randn({4})},
          {"bn.num_batches_tracked", torch::tensor(int64_t{12})}};
}

void ExpectSameTensors(const StateDict& actual, const StateDict& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (const auto& [key, tensor] : expected) {
    ASSERT_TRUE(actual.count(key)) << key;
    EXPECT_TRUE(torch::equal(actual.at(key), tensor)) << key;
  }
}

c10::impl::GenericDict AsDict(const StateDict& weights) {
  c10::impl::GenericDict dict(c10::StringType::get(), c10::AnyType::get());
  for (const auto& [key, tensor] : weights) dict.insert(key, tensor);
  return dict;
}

TEST(StateDict, ReadsPlainNestedAndOrderedDictFiles) {
  const ScopedTempDir dir("state_dict");
  const StateDict weights = SmallStateDict();

  const std::string plain = (dir.path() / "plain.pt").string();
  WriteBytes(plain, torch::pickle_save(c10::IValue(AsDict(weights))));
  ExpectSameTensors(ReadWeightsFile(plain, "Test"), weights);

  for (const char* nested : {"state_dict", "model_state_dict"}) {
    c10::impl::GenericDict checkpoint(c10::StringType::get(), c10::AnyType::get());
    checkpoint.insert("epoch", c10::IValue(int64_t{3}));
    checkpoint.insert(nested, c10::IValue(AsDict(weights)));
    const std::string path = (dir.path() / (std::string(nested) + ".pt")).string();
    WriteBytes(path, torch::pickle_save(c10::IValue(checkpoint)));
    ExpectSameTensors(ReadWeightsFile(path, "Test"), weights);
  }

  const std::string ordered = (dir.path() / "ordered.pt").string();
  testing::WriteOrderedDictFile(weights, ordered);
  ExpectSameTensors(ReadWeightsFile(ordered, "Test"), weights);
}

TEST(StateDict, BadFilesNameTheModelTheFileAndWhatIsWrong) {
  const ScopedTempDir dir("state_dict");
  const std::string missing = (dir.path() / "absent.pt").string();
  std::string message = ExpectInputError([&] { ReadWeightsFile(missing, "Test"); });
  EXPECT_NE(message.find("Test weights file '" + missing + "' is missing"), std::string::npos) << message;

  const std::string list = (dir.path() / "list.pt").string();
  WriteBytes(list, torch::pickle_save(c10::IValue(c10::List<int64_t>({1, 2}))));
  message = ExpectInputError([&] { ReadWeightsFile(list, "Test"); });
  EXPECT_NE(message.find("not a dict of tensors"), std::string::npos) << message;

  c10::impl::GenericDict with_number(c10::StringType::get(), c10::AnyType::get());
  with_number.insert("conv.weight", torch::ones({2}));
  with_number.insert("epoch", c10::IValue(int64_t{3}));
  const std::string mixed = (dir.path() / "mixed.pt").string();
  WriteBytes(mixed, torch::pickle_save(c10::IValue(with_number)));
  message = ExpectInputError([&] { ReadWeightsFile(mixed, "Test"); });
  EXPECT_NE(message.find("entry 'epoch' is not a tensor"), std::string::npos) << message;

  const std::string empty = (dir.path() / "empty.pt").string();
  WriteBytes(empty, torch::pickle_save(c10::IValue(AsDict({}))));
  message = ExpectInputError([&] { ReadWeightsFile(empty, "Test"); });
  EXPECT_NE(message.find("holds no tensors"), std::string::npos) << message;

  const std::string truncated = (dir.path() / "truncated.pt").string();
  std::vector<char> bytes = torch::pickle_save(c10::IValue(AsDict(SmallStateDict())));
  bytes.resize(bytes.size() / 2);
  WriteBytes(truncated, bytes);
  message = ExpectInputError([&] { ReadWeightsFile(truncated, "Test"); });
  EXPECT_NE(message.find("cannot read Test weights file '" + truncated + "'"), std::string::npos) << message;
  EXPECT_NE(message.find("not a complete torch.save zip archive"), std::string::npos) << message;
}

TEST(StateDict, CompareListsMissingUnexpectedAndMisshapedKeys) {
  const std::vector<TensorSpec> expected = {{"conv.weight", "float32", {4, 3, 3, 3}},
                                            {"conv.bias", "float32", {4}},
                                            {"bn.num_batches_tracked", "int64", {}},
                                            {"head.weight", "float32", {2, 4}}};
  StateDict weights = SmallStateDict();
  EXPECT_EQ(CompareStateDict(weights, expected).missing, std::vector<std::string>{"head.weight"});

  // Half-precision copies fit float32 entries: they are converted on load.
  weights["head.weight"] = torch::zeros({2, 4}, torch::kFloat16);
  EXPECT_TRUE(CompareStateDict(weights, expected).empty());

  weights["conv.bias"] = torch::zeros({5});
  weights["bn.num_batches_tracked"] = torch::zeros({}, torch::kFloat32);
  weights["extra"] = torch::zeros({1});
  const StateDictMismatch mismatch = CompareStateDict(weights, expected);
  EXPECT_EQ(mismatch.unexpected, std::vector<std::string>{"extra"});
  ASSERT_EQ(mismatch.wrong_shape.size(), 2u);
  EXPECT_EQ(mismatch.size(), 3u);
  const std::string text = mismatch.Describe();
  EXPECT_NE(text.find("conv.bias (file float32 5, expected float32 4)"), std::string::npos) << text;
  EXPECT_NE(text.find("bn.num_batches_tracked (file float32 scalar, expected int64 scalar)"), std::string::npos)
      << text;
  EXPECT_NE(text.find("unexpected keys (1):\n    extra"), std::string::npos) << text;
}

}  // namespace
}  // namespace vmap::neural
