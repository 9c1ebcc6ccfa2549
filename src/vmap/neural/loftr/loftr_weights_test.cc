// Weights: the architecture's key set against the official one, the file layouts users have, and bad files.

#include "vmap/neural/loftr/loftr_weights.h"

#include <fstream>
#include <sstream>

#include <caffe2/serialize/inline_container.h>
#include <gtest/gtest.h>
#include <torch/serialize.h>

#include "vmap/core/error.h"
#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::ExpectInputError;
using testing::WriteBytes;

using testing::SharedDir;

std::string TempPath(const std::string& name) {
  static const testing::ScopedTempDir dir("loftr_weights");
  return (dir.path() / name).string();
}

// key<TAB>dtype<TAB>shape, as the golden's state_dict_keys*.txt list the official checkpoints.
void ExpectSameAsKeyFile(const std::string& preset, const std::string& key_file) {
  std::ifstream file(key_file);
  ASSERT_TRUE(file) << key_file;
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  std::vector<std::string> ours;
  for (const auto& spec : ExpectedStateDict(LoftrPreset(preset))) {
    // The list writes a 0-d tensor's shape as "scalar".
    ours.push_back(spec.key + "\t" + spec.dtype + "\t" + (spec.shape.empty() ? "scalar" : ShapeString(spec.shape)));
  }
  std::sort(lines.begin(), lines.end());
  std::sort(ours.begin(), ours.end());
  EXPECT_EQ(ours.size(), 211u);
  EXPECT_EQ(ours, lines);
}

TEST(LoftrWeights, OutdoorKeysAndShapesEqualOfficialList) {
  SKIP_WITHOUT_SHARED();
  ExpectSameAsKeyFile("outdoor", SharedDir() + "/golden/loftr_full_random/state_dict_keys.txt");
}

TEST(LoftrWeights, IndoorKeysAndShapesEqualOfficialList) {
  SKIP_WITHOUT_SHARED();
  ExpectSameAsKeyFile("indoor", SharedDir() + "/golden/loftr_full_random/state_dict_keys_indoor_ds_new.txt");
}

TEST(LoftrWeights, SharedFilesFitTheirPresets) {
  SKIP_WITHOUT_SHARED();
  auto coarse = ReadStateDict(SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt");
  EXPECT_EQ(coarse.size(), 177u);
  EXPECT_EQ(MatchingPresets(coarse), std::vector<std::string>{"coarse"});
  auto full = ReadStateDict(SharedDir() + "/golden/loftr_full_random/weights_fp16.pt");
  EXPECT_EQ(MatchingPresets(full), (std::vector<std::string>{"outdoor", "indoor"}));
  int64_t learnable = 0;
  for (const auto& [key, t] : full) {
    if (key.find("running_") == std::string::npos && key.find("num_batches") == std::string::npos) {
      learnable += t.numel();
    }
  }
  EXPECT_EQ(learnable, 11561456);  // the paper's parameter count
}

TEST(LoftrWeights, ReadsLightningCheckpointLayout) {
  SKIP_WITHOUT_SHARED();
  // The official checkpoints keep the tensors under "state_dict" with a "matcher." prefix, beside
  // training metadata.
  auto full = ReadStateDict(SharedDir() + "/golden/loftr_full_random/weights_fp16.pt");
  c10::Dict<std::string, torch::Tensor> state;
  for (const auto& [key, t] : full) state.insert("matcher." + key, t);
  c10::impl::GenericDict checkpoint(c10::StringType::get(), c10::AnyType::get());
  checkpoint.insert("epoch", c10::IValue(int64_t{29}));
  checkpoint.insert("global_step", c10::IValue(int64_t{123}));
  checkpoint.insert("state_dict", c10::IValue(state));
  const std::string path = TempPath("lightning.ckpt");
  WriteBytes(path, torch::pickle_save(c10::IValue(checkpoint)));
  auto loaded = ReadStateDict(path);
  ASSERT_EQ(loaded.size(), full.size());
  for (const auto& [key, t] : full) {
    ASSERT_TRUE(loaded.count(key)) << key;
    EXPECT_TRUE(torch::equal(loaded.at(key), t)) << key;
  }
  CheckStateDict(loaded, LoftrPreset("outdoor"), path);
  CheckStateDict(loaded, LoftrPreset("indoor"), path);
}

TEST(LoftrWeights, ReadsLightningCheckpointWithOrderedDict) {
  SKIP_WITHOUT_SHARED();
  auto weights = ReadStateDict(SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt");
  const std::string path = TempPath("ordered.ckpt");
  {
    caffe2::serialize::PyTorchStreamWriter writer(path);
    // A PyTorch-Lightning checkpoint: the state dict as a collections.OrderedDict beside objects of classes
    // LibTorch does not know.
    testing::PickleProgram p;
    p.Raw("\x80\x02");
    p.Op('}');
    p.Op('(');
    p.String("epoch");
    p.Int(29);
    p.String("callbacks");
    p.Global("pytorch_lightning.callbacks.model_checkpoint", "ModelCheckpoint");
    p.Op(')');
    p.Op('\x81');  // NEWOBJ of a class LibTorch cannot build
    p.Op('}');
    p.String("best_model_score");
    p.Int(1);
    p.Op('s');
    p.Op('b');
    p.String("state_dict");
    p.OrderedStateDict(weights, "matcher.", 0, writer);
    p.Op('u');
    p.Op('.');
    writer.writeRecord("data.pkl", p.code().data(), p.code().size());
    writer.writeEndOfFile();
  }
  auto loaded = ReadStateDict(path);
  ASSERT_EQ(loaded.size(), weights.size());
  for (const auto& [key, t] : weights) {
    ASSERT_TRUE(loaded.count(key)) << key;
    EXPECT_TRUE(torch::equal(loaded.at(key), t)) << key;
  }
  CheckStateDict(loaded, LoftrPreset("coarse"), path);
}

TEST(LoftrWeights, WrongPresetListsKeysAndNamesTheRightOne) {
  SKIP_WITHOUT_SHARED();
  const std::string path = SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt";
  auto coarse = ReadStateDict(path);
  const std::string message = ExpectInputError([&] { CheckStateDict(coarse, LoftrPreset("outdoor"), path); });
  EXPECT_NE(message.find("missing keys"), std::string::npos) << message;
  EXPECT_NE(message.find("loftr_coarse.layers.4.q_proj.weight"), std::string::npos) << message;  // missing
  EXPECT_NE(message.find("backbone.layer3_outconv2.0.weight"), std::string::npos) << message;    // unexpected
  EXPECT_NE(message.find("backbone.conv1.weight (file float32 8x1x7x7, expected float32 128x1x7x7)"), std::string::npos)
      << message;
  EXPECT_NE(message.find("--loftr-model coarse"), std::string::npos) << message;
}

TEST(LoftrWeights, ChangedShapeIsReported) {
  SKIP_WITHOUT_SHARED();
  const std::string path = SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt";
  auto weights = ReadStateDict(path);
  weights["loftr_coarse.layers.1.q_proj.weight"] = torch::zeros({32, 16});
  const std::string message = ExpectInputError([&] { CheckStateDict(weights, LoftrPreset("coarse"), path); });
  EXPECT_NE(message.find("loftr_coarse.layers.1.q_proj.weight (file float32 32x16, expected float32 32x32)"),
            std::string::npos)
      << message;
}

TEST(LoftrWeights, TruncatedAndForeignFilesGiveClearErrors) {
  SKIP_WITHOUT_SHARED();
  std::ifstream source(SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt", std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
  for (size_t keep : {size_t{0}, size_t{100}, bytes.size() / 2, bytes.size() - 10}) {
    const std::string path = TempPath("truncated_" + std::to_string(keep) + ".pt");
    WriteBytes(path, std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep)));
    const std::string message = ExpectInputError([&] { ReadStateDict(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
  }
  const std::string text_path = TempPath("notes.txt");
  WriteBytes(text_path, {'h', 'e', 'l', 'l', 'o'});
  EXPECT_NE(ExpectInputError([&] { ReadStateDict(text_path); }).find("not a complete torch.save"), std::string::npos);
  const std::string list_path = TempPath("list.pt");
  WriteBytes(list_path, torch::pickle_save(c10::IValue(c10::List<int64_t>({1, 2}))));
  EXPECT_NE(ExpectInputError([&] { ReadStateDict(list_path); }).find("not a dict"), std::string::npos);
  EXPECT_NE(ExpectInputError([&] { ReadStateDict(TempPath("absent.pt")); }).find("is missing"), std::string::npos);
}

}  // namespace
}  // namespace vmap::neural
