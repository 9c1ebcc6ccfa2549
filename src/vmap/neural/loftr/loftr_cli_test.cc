// `vmap match` and `vmap weights` end to end, through the built binary.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/testing/golden_util.h"

namespace vmap::neural {
namespace {

using testing::LoadTensorDict;
using testing::SharedDir;
namespace fs = std::filesystem;
using testing::RunVmap;
using testing::ScopedTempDir;

TEST(VmapMatch, WritesReferenceMatchesAndVerification) {
  SKIP_WITHOUT_SHARED();
  const std::string pair = SharedDir() + "/golden/loftr_coarse/rccar_000000_000006";
  const ScopedTempDir scoped("match");
  const fs::path& dir = scoped.path();
  const std::string json_path = (dir / "m.json").string();
  const auto r = RunVmap("match " + pair + "/input0.png " + pair + "/input1.png --matcher loftr --weights " +
                         SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt --json " + json_path);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("tentative   86"), std::string::npos) << r.output;
  std::ifstream file(json_path);
  const auto j = nlohmann::json::parse(file);
  const auto g = LoadTensorDict(pair + "/golden.pt");
  ASSERT_EQ(j["matches"].size(), static_cast<size_t>(g.at("mkpts0_c").size(0)));
  EXPECT_EQ(j["num_tentative"].get<int>(), 86);
  for (size_t k = 0; k < j["matches"].size(); ++k) {
    const auto& m = j["matches"][k];
    EXPECT_EQ(m["x0"].get<float>(), g.at("mkpts0_c")[k][0].item<float>());
    EXPECT_EQ(m["y1"].get<float>(), g.at("mkpts1_c")[k][1].item<float>());
  }
  int inliers = 0;
  for (const auto& m : j["matches"]) inliers += m["inlier"].get<bool>();
  EXPECT_EQ(inliers, j["num_verified"].get<int>());
  EXPECT_EQ(j["verified"].get<bool>(), !j["F"].is_null());
}

TEST(VmapMatch, BadInputExitsWithStatus2) {
  SKIP_WITHOUT_SHARED();
  const std::string pair = SharedDir() + "/golden/loftr_coarse/rccar_000000_000006";
  auto r = RunVmap("match " + pair + "/input0.png /nonexistent.png --matcher loftr");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent.png"), std::string::npos) << r.output;
  r = RunVmap("match " + pair + "/input0.png " + pair + "/input1.png --matcher loftr --loftr-model outdoor --weights " +
              SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--loftr-model coarse"), std::string::npos) << r.output;
}

TEST(VmapWeights, ImportsIntoCacheAndReportsIt) {
  SKIP_WITHOUT_SHARED();
  const ScopedTempDir scoped("cache");
  const fs::path& cache = scoped.path();
  const std::string env = std::string("VMAP_WEIGHTS_DIR=") + cache.string() + " ";
  const std::string student = SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt";
  // A file of the wrong architecture is refused and nothing enters the cache.
  EXPECT_NE(RunVmap("weights --import " + student + " --model outdoor --no-verify", env).status, 0);
  EXPECT_FALSE(fs::exists(cache / "outdoor_ds.ckpt"));
  // The student goes in, and `vmap weights` then lists the cached copy as the one used.
  const auto imported = RunVmap("weights --import " + student + " --model coarse", env);
  ASSERT_EQ(imported.status, 0) << imported.output;
  EXPECT_TRUE(fs::exists(cache / "loftr_coarse_teacher.pt"));
  const std::string listing = RunVmap("weights", env).output;
  EXPECT_NE(listing.find("[used]    " + (cache / "loftr_coarse_teacher.pt").string()), std::string::npos) << listing;
  EXPECT_NE(listing.find("vmap weights --download outdoor"), std::string::npos) << listing;
}

// With the coarse student, `vmap build` looks for key images by bisection unless told otherwise: fewer frames
// compared than Algorithm 1's scan, and a valid map (every link that is not broken at S >= tau).
TEST(VmapBuildLoftr, BisectSearchComparesFewerFramesAndSequentialIsTheDefault) {
  SKIP_WITHOUT_SHARED();
  const ScopedTempDir scoped("build_search");
  const fs::path& dir = scoped.path();
  const std::string common = "build " + SharedDir() + "/data/rccar_room/images --last 59 --matcher loftr -q -o ";
  auto load = [](const fs::path& map_dir) {
    std::ifstream file(map_dir / "map.json");
    return nlohmann::json::parse(file);
  };
  auto r = RunVmap(common + (dir / "bisect").string() + " --search bisect");
  ASSERT_EQ(r.status, 0) << r.output;
  r = RunVmap(common + (dir / "auto").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto bisect = load(dir / "bisect"), sequential = load(dir / "auto");
  EXPECT_EQ(bisect["options"]["search"], "bisect");
  EXPECT_EQ(sequential["options"]["search"], "sequential");
  EXPECT_EQ(bisect["num_frames"], 60);
  EXPECT_LT(bisect["evaluations"]["frame"].size(), sequential["evaluations"]["frame"].size());
  EXPECT_EQ(bisect["key_images"].back()["frame_index"], 59);
  for (const auto& link : bisect["links"]) {
    if (!link["below_tau"].get<bool>()) {
      EXPECT_GE(link["similarity"].get<double>(), 0.5);
    }
  }
}

}  // namespace
}  // namespace vmap::neural
