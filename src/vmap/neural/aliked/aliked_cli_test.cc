// `vmap match|build|sweep|weights` with ALIKED, end to end through the built binary.

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <torch/torch.h>

#include "vmap/features/matcher_registry.h"
#include "vmap/testing/golden_util.h"
#include "vmap/testing/localization_test_util.h"

namespace vmap::neural {
namespace {

using testing::SharedDir;
namespace fs = std::filesystem;
using testing::RunVmap;
using TempDir = testing::ScopedTempDir;

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

TEST(AlikedCli, MatchFindsTheReferenceMatchCount) {
  SKIP_WITHOUT_SHARED();
  const std::string pair = SharedDir() + "/golden/aliked-t16/rccar_000000_000006";
  const auto meta = testing::LoadJson(pair + "/golden.json");
  const TempDir dir("match");
  const auto json_path = dir.path() / "m.json";
  // Default weights: found in the shared data folder; upstream's pair settings.
  const auto r = RunVmap("match " + pair + "/input0.png " + pair +
                         "/input1.png --matcher aliked --aliked-top-k 1000 "
                         "--aliked-min-similarity 0.75 --json " +
                         json_path.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = ReadJson(json_path);
  EXPECT_NEAR(j["num_tentative"].get<int>(), meta["counts"]["mnn0p75"].get<int>(), 3);
  EXPECT_GT(j["num_verified"].get<int>(), 0);
  EXPECT_NE(r.output.find("\"type\":\"aliked\""), std::string::npos) << r.output;
}

TEST(AlikedCli, BuildAndSweepRecordTheMatcher) {
  SKIP_WITHOUT_SHARED();
  const TempDir dir("build");
  const std::string input = SharedDir() + "/data/rccar_room/images";
  auto r = RunVmap("build " + input + " --last 14 --matcher aliked --aliked-model t16 -q -o " +
                   (dir.path() / "map").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto map = ReadJson(dir.path() / "map/map.json");
  EXPECT_EQ(map["num_frames"].get<int>(), 15);
  const auto& matcher = map["options"]["matcher"];
  EXPECT_EQ(matcher["type"], "aliked") << matcher.dump();
  EXPECT_EQ(matcher["model"], "aliked-t16");
  // Without --tau, ALIKED's own default (its S stays high as its matches thin out).
  EXPECT_DOUBLE_EQ(map["options"]["tau"].get<double>(), DefaultTau("aliked"));
  EXPECT_GT(DefaultTau("aliked"), DefaultTau("orb"));
  EXPECT_GE(map["key_images"].size(), 2u);
  for (const auto& link : map["links"]) {
    if (!link["below_tau"].get<bool>()) {
      EXPECT_GE(link["verified"].get<int>(), 8) << link.dump();
    }
  }
  r = RunVmap("info " + (dir.path() / "map").string());
  EXPECT_NE(r.output.find("aliked"), std::string::npos) << r.output;

  r = RunVmap("sweep " + input + " --last 9 --matcher aliked --thresholds 0.5:0.7:0.1 -q -o " +
              (dir.path() / "sweep").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto sweep = ReadJson(dir.path() / "sweep/sweep.json");
  EXPECT_EQ(sweep["rows"].size(), 3u);
  EXPECT_EQ(sweep["options"]["search"], "sequential") << "a sweep compares every frame, deep matcher or not";
}

TEST(AlikedCli, CudaWithoutCudaAndWrongWeightsAreRefused) {
  SKIP_WITHOUT_SHARED();
  const std::string pair = SharedDir() + "/golden/aliked-t16/rccar_000000_000006";
  if (!torch::cuda::is_available()) {
    const auto r = RunVmap("match " + pair + "/input0.png " + pair + "/input1.png --matcher aliked --device cuda");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--device cuda"), std::string::npos) << r.output;
  }
  const auto r = RunVmap("match " + pair + "/input0.png " + pair + "/input1.png --matcher aliked --weights " +
                         SharedDir() + "/weights/aliked/aliked-n16.pt");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("fits --aliked-model n16"), std::string::npos) << r.output;
}

TEST(AlikedCli, WeightsListsImportsAndVerifiesAlikedFiles) {
  SKIP_WITHOUT_SHARED();
  const TempDir cache("cache");
  const std::string env = "VMAP_WEIGHTS_DIR=" + cache.path().string() + " ";
  const std::string t16 = SharedDir() + "/weights/aliked/aliked-t16.pt";
  const std::string n16 = SharedDir() + "/weights/aliked/aliked-n16.pt";
  auto listing = RunVmap("weights", env);
  ASSERT_EQ(listing.status, 0) << listing.output;
  EXPECT_NE(listing.output.find("aliked-t16"), std::string::npos) << listing.output;
  EXPECT_NE(listing.output.find("https://github.com/Shiaoming/ALIKED/raw/main/models/aliked-n16.pth"),
            std::string::npos)
      << listing.output;
  // The wrong model's file is refused and nothing enters the cache.
  auto r = RunVmap("weights --import " + n16 + " --model aliked-t16", env);
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("(it fits aliked-n16); give --model as the file fits"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("XFeat"), std::string::npos) << "the other models' refusals bury the answer\n" << r.output;
  EXPECT_FALSE(fs::exists(cache.path() / "aliked-t16.pth"));
  r = RunVmap("weights --import " + t16 + " --model aliked-t16", env);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(cache.path() / "aliked-t16.pth"));
  listing = RunVmap("weights", env);
  EXPECT_NE(listing.output.find("[used]    " + (cache.path() / "aliked-t16.pth").string()), std::string::npos)
      << listing.output;
  r = RunVmap("weights --verify " + n16, env);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("fits         aliked-n16"), std::string::npos) << r.output;
}

// Key-image features of a map are computed at the first `vmap localize` start and read from the map's cache after.
TEST(AlikedCli, SecondLocalizeStartReadsTheKeyImagesFromTheCache) {
  SKIP_WITHOUT_SHARED();
  const TempDir dir("cache");
  const std::string input = SharedDir() + "/data/rccar_room/images";
  const auto r =
      RunVmap("build " + input + " --last 8 --tau 0.6 --matcher aliked -q -o " + (dir.path() / "map").string());
  ASSERT_EQ(r.status, 0) << r.output;
  ::vmap::testing::ExpectSecondLocalizeReadsTheCache(dir.path() / "map", input, "--last 8");
}

}  // namespace
}  // namespace vmap::neural
