// `vmap match`, `vmap build` and `vmap weights` with XFeat, through the built binary, and `vmap localize` on
// michigan_seasons' routes (corridor_conditions' runs: xfeat_corridor_cli_test.cc).

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <torch/torch.h>

#include "vmap/core/file_name_encoding.h"
#include "vmap/testing/golden_util.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/localize_cli_test_util.h"

namespace vmap::neural {
namespace {

using testing::SharedDir;
namespace fs = std::filesystem;
using testing::RunVmap;
using ::vmap::testing::SteeredFrames;
using TempDir = testing::ScopedTempDir;

std::string FoldedWeights() { return SharedDir() + "/weights/xfeat/xfeat_folded.pt"; }

// A localization CSV's cells, every row but its `seconds`, the time the frame took (the one column two runs differ by).
std::vector<std::vector<std::string>> CsvWithoutSeconds(const fs::path& csv) {
  std::ifstream in(csv);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream cells_of(line);
    for (std::string cell; std::getline(cells_of, cell, ',');) cells.push_back(cell);
    rows.push_back(std::move(cells));
  }
  if (rows.empty()) return rows;
  const auto seconds = std::find(rows.front().begin(), rows.front().end(), "seconds") - rows.front().begin();
  for (auto& row : rows) {
    if (seconds < static_cast<long>(row.size())) row.erase(row.begin() + seconds);
  }
  return rows;
}

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

// A weights file whose name is not UTF-8 is recorded percent-encoded (JSON must be UTF-8: the map's writer raised
// nlohmann's type_error 316, "an unexpected error") and found again from it; the threads per call, a run setting
// that changes no result, are not recorded (two maps of the same input differed by them alone).
TEST(VmapXfeat, AMapRecordsItsWeightsWhateverTheirNameAndNotItsThreads) {
  SKIP_WITHOUT_SHARED();
  TempDir dir("weights_name");
  const fs::path weights = dir.path() / "xfeat\xff.pt";
  fs::copy_file(SharedDir() + "/weights/xfeat/xfeat_folded.pt", weights);
  const std::string input = SharedDir() + "/data/rccar_room/images --last 6 -q --matcher xfeat";
  for (const char* threads : {"1", "2"}) {
    const auto r = RunVmap("build " + input + " --xfeat-threads " + threads + " --weights '" + weights.string() +
                           "' -o " + (dir.path() / ("map" + std::string(threads))).string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  const auto map_json = [&](const char* name) {
    std::ifstream file(dir.path() / name / "map.json");
    auto j = nlohmann::json::parse(file);
    j.erase("seconds");  // the run's time, the one field two runs may differ by
    return j;
  };
  EXPECT_EQ(map_json("map1"), map_json("map2"));
  const auto j = map_json("map1");
  EXPECT_EQ(j["options"]["matcher"]["weights"], EncodeFileName(weights.string()));
  EXPECT_FALSE(j["options"]["matcher"].contains("threads")) << j["options"]["matcher"];
  const auto localize = RunVmap("localize " + (dir.path() / "map1").string() + " " + SharedDir() +
                                "/data/rccar_room/images --last 2 --no-cache -v");
  ASSERT_EQ(localize.status, 0) << localize.output;
  EXPECT_EQ(localize.output.find("are not here; searching the weights directories"), std::string::npos)
      << localize.output;
}

// A map built where its weights lay is followed where they lie elsewhere: --weights names the file, with no search and
// no warning, and the frames localize as with the map's own file. Weights of another model are refused naming the
// file, and so is --weights for a map whose matcher reads none; --add-experience-to takes it as localize does.
TEST(VmapXfeat, LocalizeReadsTheWeightsItIsGivenOfTheMapsModel) {
  SKIP_WITHOUT_SHARED();
  TempDir dir;
  const fs::path built_with = dir.path() / "built_with.pt", robots = dir.path() / "robots.pt";
  fs::copy_file(FoldedWeights(), built_with);
  const std::string input = SharedDir() + "/data/rccar_room/images --last 5";
  const std::string map = (dir.path() / "map").string();
  auto r = RunVmap("build " + input + " --matcher xfeat --weights " + built_with.string() + " -q -o " + map);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto localize_csv = [&](const std::string& flags, const std::string& name) {
    const fs::path csv = dir.path() / name;
    const auto run = RunVmap("localize " + map + " " + input + " --no-cache --csv " + csv.string() + " " + flags);
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_EQ(run.output.find("are not here"), std::string::npos) << run.output;
    return CsvWithoutSeconds(csv);
  };
  const auto with_map_weights = localize_csv("", "map.csv");
  ASSERT_GE(with_map_weights.size(), 6u);
  fs::rename(built_with, robots);
  EXPECT_EQ(localize_csv("--weights " + robots.string(), "robot.csv"), with_map_weights);

  r = RunVmap("localize " + map + " " + input + " -q --weights " + SharedDir() + "/weights/aliked/aliked-n16.pt");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--weights '" + SharedDir() +
                          "/weights/aliked/aliked-n16.pt' are not weights of the map's "
                          "xfeat"),
            std::string::npos)
      << r.output;
  r = RunVmap("build " + SharedDir() + "/data/rccar_room/images --last 5 --add-experience-to " + map +
              " -q --weights " + SharedDir() + "/weights/aliked/aliked-n16.pt");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("are not weights of the map's xfeat"), std::string::npos) << r.output;
  for (const std::string& command :
       {"localize " + map + " " + input, "build " + input + " --add-experience-to " + map}) {
    r = RunVmap(command + " -q --weights " + (dir.path() / "nowhere.pt").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("nowhere.pt' is not a file"), std::string::npos) << r.output;
  }
  // Another error than the file's is not blamed on it.
  if (!torch::cuda::is_available()) {
    r = RunVmap("localize " + map + " " + input + " -q --device cuda --weights " + robots.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_EQ(r.output.find("are not weights"), std::string::npos) << r.output;
  }
  r = RunVmap("build " + SharedDir() + "/data/rccar_room/images --last 5 --add-experience-to " + map +
              " -q --weights " + robots.string());
  EXPECT_EQ(r.status, 0) << r.output;

  const std::string orb_map = (dir.path() / "orb").string();
  ASSERT_EQ(RunVmap("build " + input + " -q -o " + orb_map).status, 0);
  // Said, not refused: a robot's weights parameter may stay set for a map of another matcher.
  r = RunVmap("localize " + orb_map + " " + input + " --weights " + robots.string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("are not read: the map's matcher orb reads none"), std::string::npos) << r.output;
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

// The device is where a run computes, not part of the map: a map taught with --device cuda (on a GPU workstation) is
// followed on the CPU with --device cpu, and every frame is localized as on a map taught on the CPU.
TEST(VmapXfeat, AMapTaughtOnAGpuIsFollowedOnTheCpu) {
  SKIP_WITHOUT_SHARED();
  TempDir dir;
  const std::string input = SharedDir() + "/data/rccar_room/images --last 6";
  auto r = RunVmap("build " + input + " --matcher xfeat -q -o " + (dir.path() / "cpu").string());
  ASSERT_EQ(r.status, 0) << r.output;
  // The same map as a GPU would have recorded it.
  fs::create_directories(dir.path() / "cuda");
  fs::copy(dir.path() / "cpu", dir.path() / "cuda", fs::copy_options::recursive);
  std::string text;
  {
    std::ifstream in(dir.path() / "cuda/map.json");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const size_t device = text.find("\"device\": \"cpu\"");
  ASSERT_NE(device, std::string::npos);
  text.replace(device, std::string("\"device\": \"cpu\"").size(), "\"device\": \"cuda\"");
  std::ofstream(dir.path() / "cuda/map.json") << text;
  fs::remove(dir.path() / "cuda/localization_cache.bin");
  const auto localize = [&](const std::string& map, const std::string& flags) {
    const fs::path csv = dir.path() / (map + ".csv");
    const auto run =
        RunVmap("localize " + (dir.path() / map).string() + " " + input + " -q --csv " + csv.string() + " " + flags);
    EXPECT_EQ(run.status, 0) << run.output;
    return CsvWithoutSeconds(csv);
  };
  const auto on_cpu = localize("cpu", "");
  ASSERT_GE(on_cpu.size(), 7u);
  EXPECT_EQ(localize("cuda", "--device cpu"), on_cpu);
  if (!torch::cuda::is_available()) {
    r = RunVmap("localize " + (dir.path() / "cuda").string() + " " + input + " -q");
    EXPECT_EQ(r.status, 2) << r.output;
  }
  r = RunVmap("localize " + (dir.path() / "cpu").string() + " " + input + " -q --device gpu");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--device 'gpu' is not a device"), std::string::npos) << r.output;
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
  // A file of no model's is refused with every model's reason, not the first model's alone.
  const fs::path not_weights = cache.path() / "notes.txt";
  std::ofstream(not_weights) << "not weights\n";
  r = RunVmap("weights --verify " + not_weights.string(), env);
  EXPECT_EQ(r.status, 2) << r.output;
  for (const char* model : {"aliked: ", "loftr: ", "xfeat: "}) {
    EXPECT_NE(r.output.find(model), std::string::npos) << model << "\n" << r.output;
  }
  // The folded file is not the published xfeat.pt: refused by its git blob id, imported without the check,
  // and then used from the cache.
  r = RunVmap("weights --import " + FoldedWeights() + " --model xfeat", env);
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("is xfeat (folded layout), not the published xfeat.pt whose git blob id vmap checks; import "
                          "it with --no-verify"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("corrupt"), std::string::npos) << r.output;
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
  EXPECT_NE(r.output.find("does not fit --model xfeat (it fits coarse); give --model as the file fits"),
            std::string::npos)
      << r.output;
}

// Key-image features of a map are computed at the first `vmap localize` start and read from the map's cache after.
TEST(VmapXfeat, SecondLocalizeStartReadsTheKeyImagesFromTheCache) {
  SKIP_WITHOUT_SHARED();
  const TempDir dir("cache");
  const std::string input = SharedDir() + "/data/rccar_room/images";
  const fs::path weights = dir.path() / "xfeat.pt";
  fs::copy_file(FoldedWeights(), weights);
  const auto r = RunVmap("build " + input + " --last 8 --tau 0.6 --matcher xfeat --xfeat-top-k 1000 --weights " +
                         weights.string() + " -q -o " + (dir.path() / "map").string());
  ASSERT_EQ(r.status, 0) << r.output;
  ::vmap::testing::ExpectSecondLocalizeReadsTheCache(dir.path() / "map", input, "--last 8");
  // Weights replaced in place (here: written again) may extract otherwise: the cache is not read.
  fs::last_write_time(weights, fs::last_write_time(weights) + std::chrono::seconds(5));
  const fs::path json = dir.path() / "after.json";
  const auto again =
      RunVmap("localize " + (dir.path() / "map").string() + " " + input + " --last 2 -q --json " + json.string());
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(json))["key_image_cache"], "written");
}

// michigan_seasons' session `query` (its five places) against an XFeat map of session `teach`'s, built in `dir` as
// bench/route_conditions.py builds it (`--tau 1`): `vmap localize`'s map and images arguments; "" without the data.
std::string MichiganRoute(const fs::path& dir, const std::string& query, const std::string& teach) {
  const fs::path images = fs::path(SharedDir()) / "data/michigan_seasons/images";
  if (!fs::exists(images)) return "";
  for (const std::string& session : {query, teach}) {
    fs::create_directories(dir / session);
    for (int place = 1; place <= 5; ++place) {
      fs::create_symlink(images / (session + "0" + std::to_string(place) + ".png"),
                         dir / session / (std::to_string(place) + ".png"));
    }
  }
  const auto built = RunVmap("build " + ::vmap::testing::Quote(dir / teach) + " --tau 1 --matcher xfeat --weights " +
                             FoldedWeights() + " -q -o " + ::vmap::testing::Quote(dir / "map"));
  EXPECT_EQ(built.status, 0) << built.output;
  return ::vmap::testing::Quote(dir / "map") + " " + ::vmap::testing::Quote(dir / query);
}

// Frames steered by at key images more than `off` from their place (michigan: frame i's is key image i).
int SteeredOff(const std::vector<std::pair<int, int>>& frames, int off) {
  return static_cast<int>(
      std::count_if(frames.begin(), frames.end(), [&](const auto& f) { return std::abs(f.second - f.first) > off; }));
}

// The same rule across seasons: michigan_seasons' session 03 against an XFeat map of session 08's five places (`--tau
// 1`), at the verifier's seed 2. Place 3 verifies nothing anywhere (lost at key image 1); place 4 verifies 17 chance
// matches at key image 1 (log10 NFA -5.5) and was tracked there, and place 5 likewise (19 at -6.1), three key images
// off: the tracker never compared the key images ahead, which verify 139 and 329 matches. Two places of a route share
// no scene: each frame held by little beyond chance is asked where it is, and places 4 and 5 are at key images 3 and 4.
TEST(VmapXfeat, AFrameOfAnotherPlaceThanTheFrameBeforeIsAskedWhereItIs) {
  SKIP_WITHOUT_SHARED();
  const TempDir dir("michigan");
  const std::string route = MichiganRoute(dir.path(), "03", "08");
  if (route.empty()) GTEST_SKIP() << "michigan_seasons is not present";
  auto steered = [&](const std::string& flags) {
    return SteeredFrames(route + " --verifier-seed 2" + flags, dir.path() / "run.csv");
  };
  const std::vector<std::pair<int, int>> asked = steered("");
  EXPECT_EQ(SteeredOff(asked, 2), 0) << ::testing::PrintToString(asked);
  EXPECT_GE(SteeredOff(steered(" --scene-change-log10-nfa 0 --no-look-past-weak-next"), 2), 1)
      << "the test no longer reaches a frame tracked far";
}

// ... but not a frame its key image holds far beyond chance (docs/localize.md, the same rule): michigan_seasons'
// session 02 against session 03's map at the verifier's seed 0 (place p's key image is p - 1). Place 3 is tracked at
// key image 2 at log10 NFA -320, its comparison with place 2 as weak as every michigan frame's with the one before;
// asked again (as before the rule was narrowed: --scene-change-tracked-log10-nfa -1000), the frame's ranking undid its
// step on, and places 3-5 were steered by a key image behind (at 1, 2 and 3, at log10 NFA -8.2 to -2.9).
TEST(VmapXfeat, AFrameItsKeyImageHoldsFarBeyondChanceIsNotAskedAgain) {
  SKIP_WITHOUT_SHARED();
  const TempDir dir("michigan");
  const std::string route = MichiganRoute(dir.path(), "02", "03");
  if (route.empty()) GTEST_SKIP() << "michigan_seasons is not present";
  auto steered = [&](const std::string& flags) {
    return SteeredFrames(route + " --start-key 0 --verifier-seed 0" + flags, dir.path() / "run.csv");
  };
  const std::vector<std::pair<int, int>> held = steered("");
  EXPECT_EQ(held.size(), 5u) << ::testing::PrintToString(held);
  EXPECT_EQ(SteeredOff(held, 0), 0) << ::testing::PrintToString(held);
  EXPECT_GE(SteeredOff(steered(" --scene-change-tracked-log10-nfa -1000"), 0), 1)
      << "the test no longer reaches a right frame whose step on the question undid";
}

}  // namespace
}  // namespace vmap::neural
