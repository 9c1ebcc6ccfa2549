// `vmap match`, `vmap build` and `vmap weights` with XFeat, through the built binary.

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <torch/torch.h>

#include "vmap/testing/golden_util.h"
#include "vmap/testing/localization_test_util.h"

namespace vmap::neural {
namespace {

using testing::SharedDir;
namespace fs = std::filesystem;
using testing::RunVmap;
using TempDir = testing::ScopedTempDir;

std::string FoldedWeights() { return SharedDir() + "/weights/xfeat/xfeat_folded.pt"; }

TEST(VmapXfeat, MatchWritesTheReferenceMatches) {
  SKIP_WITHOUT_SHARED();
  // KITTI is grey, so `vmap match` (which reads images as grey) sees the reference's input.
  const std::string pair = SharedDir() + "/golden/xfeat/kitti07_000010_000014";
  TempDir dir("match");
  const std::string json_path = (dir.path() / "m.json").string();
  const auto r = RunVmap("match " + pair + "/input0.png " + pair + "/input1.png --matcher xfeat --weights " +
                         FoldedWeights() + " --json " + json_path);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("matcher     xfeat"), std::string::npos) << r.output;
  std::ifstream file(json_path);
  const auto j = nlohmann::json::parse(file);
  const auto reference = testing::LoadTensorDict(pair + "/golden.pt").at("mkpts0_mnn0p82");
  EXPECT_NEAR(j["num_tentative"].get<double>(), static_cast<double>(reference.size(0)), 2.0);
  ASSERT_EQ(j["matches"].size(), j["num_tentative"].get<size_t>());
}

TEST(VmapXfeat, BuildRecordsTheMatcherAndItsOptions) {
  SKIP_WITHOUT_SHARED();
  TempDir dir("build");
  const fs::path map = dir.path() / "map";
  const auto r = RunVmap("build " + SharedDir() + "/data/rccar_room/images --last 11 --tau 0.2 --matcher xfeat " +
                         "--xfeat-top-k 1000 --xfeat-min-similarity 0.9 -q -o " + map.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream file(map / "map.json");
  const auto j = nlohmann::json::parse(file);
  const auto& matcher = j["options"]["matcher"];
  EXPECT_EQ(matcher["type"], "xfeat") << matcher;
  EXPECT_EQ(matcher["top_k"], 1000);
  EXPECT_EQ(matcher["min_similarity"], 0.9);
  EXPECT_EQ(matcher["weights_layout"], "folded");
  ASSERT_GE(j["links"].size(), 1u);
  for (const auto& link : j["links"]) EXPECT_GT(link["verified"].get<int>(), 50) << link;
  const auto info = RunVmap("info " + map.string());
  EXPECT_EQ(info.status, 0) << info.output;
}

TEST(VmapXfeat, BadOptionsAndMissingCudaAreRefused) {
  SKIP_WITHOUT_SHARED();
  const std::string pair = SharedDir() + "/golden/xfeat/rccar_000000_000006";
  const std::string images = pair + "/input0.png " + pair + "/input1.png";
  auto r = RunVmap("match " + images + " --matcher xfeat --xfeat-top-k 0");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--xfeat-top-k"), std::string::npos) << r.output;
  r = RunVmap("match " + images + " --matcher xfeat --weights " + SharedDir() +
              "/weights/loftr_coarse/loftr_coarse_teacher.pt");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("fits no XFeat layout"), std::string::npos) << r.output;
  if (!torch::cuda::is_available()) {
    r = RunVmap("match " + images + " --matcher xfeat --device cuda");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--device cuda"), std::string::npos) << r.output;
  }
}

TEST(VmapXfeat, WeightsKnowsXfeatAndItsLayouts) {
  SKIP_WITHOUT_SHARED();
  TempDir cache("cache");
  const std::string env = "VMAP_WEIGHTS_DIR=" + cache.path().string() + " ";
  // Listed with the official file's download, and the shared folded copy found.
  auto r = RunVmap("weights", env);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("xfeat    XFeat"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("weights/xfeat/xfeat_folded.pt"), std::string::npos) << r.output;
  r = RunVmap("weights --verify " + FoldedWeights(), env);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("xfeat (folded layout)"), std::string::npos) << r.output;
  // The folded file is not the published xfeat.pt: refused by its git blob id, imported without the check,
  // and then used from the cache.
  r = RunVmap("weights --import " + FoldedWeights() + " --model xfeat", env);
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("git blob id"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(cache.path() / "xfeat.pt"));
  r = RunVmap("weights --import " + FoldedWeights() + " --model xfeat --no-verify", env);
  ASSERT_EQ(r.status, 0) << r.output;
  ASSERT_TRUE(fs::exists(cache.path() / "xfeat.pt"));
  const std::string pair = SharedDir() + "/golden/xfeat/labfloor_00100_00130";
  r = RunVmap("match " + pair + "/input0.png " + pair + "/input1.png --matcher xfeat --xfeat-top-k 500", env);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find((cache.path() / "xfeat.pt").string()), std::string::npos) << r.output;
  // A LoFTR file is no XFeat file.
  r = RunVmap("weights --import " + SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt --model xfeat " +
                  "--no-verify",
              env);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("fits no XFeat layout"), std::string::npos) << r.output;
}

// Key-image features of a map are computed at the first `vmap localize` start and read from the map's cache after.
TEST(VmapXfeat, SecondLocalizeStartReadsTheKeyImagesFromTheCache) {
  SKIP_WITHOUT_SHARED();
  const TempDir dir("cache");
  const std::string input = SharedDir() + "/data/rccar_room/images";
  const auto r = RunVmap("build " + input + " --last 8 --tau 0.6 --matcher xfeat --xfeat-top-k 1000 --weights " +
                         FoldedWeights() + " -q -o " + (dir.path() / "map").string());
  ASSERT_EQ(r.status, 0) << r.output;
  ::vmap::testing::ExpectSecondLocalizeReadsTheCache(dir.path() / "map", input, "--last 8");
}

}  // namespace
}  // namespace vmap::neural
