// End-to-end tests of `vmap localize` on corridor_conditions with ORB that a run's results do not change with how
// its comparisons are made: on other threads, or with the map's verifier seed given explicitly (every CSV column but
// the time the same); another seed verifies other matches.

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/testing/localize_cli_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
using ::vmap::testing::CsvColumn;
using ::vmap::testing::Lines;
using ::vmap::testing::Quote;
using ::vmap::testing::RunVmap;
using ::vmap::testing::Shared;
namespace {

// `vmap localize` of `map` on corridor_conditions' first `last` + 1 repeat frames with more `flags`, into `csv` and
// `json`: each CSV column but the time, by name (none when the run fails).
std::map<std::string, std::vector<std::string>> RepeatColumnsButTheTime(const fs::path& map, int last,
                                                                        const std::string& flags, const fs::path& csv,
                                                                        const fs::path& json) {
  std::string out;
  const fs::path repeat = Shared() / "data/corridor_conditions/repeat";
  if (RunVmap("localize " + Quote(map) + " " + Quote(repeat) + " --last " + std::to_string(last) + " -q --csv " +
                  Quote(csv) + " --json " + Quote(json) + flags,
              &out) != 0) {
    ADD_FAILURE() << out;
    return {};
  }
  std::stringstream header(Lines(csv).at(0));
  std::map<std::string, std::vector<std::string>> columns;
  for (std::string name; std::getline(header, name, ',');) {
    if (name != "seconds") columns[name] = CsvColumn(csv, name);
  }
  return columns;
}

TEST(LocalizeCli, ComparisonsMadeOnOtherThreadsChangeNoResult) {
  // corridor_conditions with ORB: its frames are refused at their tracked key images, compared with their rivals,
  // relocalized and questioned. The comparisons a frame is about to make are made meanwhile on a second core
  // (LocalizerOptions::comparison_threads; docs/measurements/localization-conditions.md, "Where ORB's corridor time
  // goes"), and the extraction threads compare each frame ahead with the key images the estimate before it was at
  // (LocalizeSequenceOptions::compare_ahead). Every result is as when each comparison is made in turn, bit for bit:
  // the CSV's columns but the time, and the JSON's confidence and belief, whose sums run over the frame's comparisons.
  const fs::path data = Shared() / "data/corridor_conditions";
  if (Shared().empty() || !fs::exists(data)) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(data / "teach") + " -q -o " + Quote(tmp.path() / "map"), &out), 0) << out;
  // Per run, each CSV column but the time, by name, and each JSON frame but its time.
  std::vector<std::map<std::string, std::vector<std::string>>> runs;
  std::vector<nlohmann::json> json_frames;
  for (const std::string flags : {"", " --comparison-threads 1", " --comparison-threads 1 --no-compare-ahead"}) {
    const fs::path csv = tmp.path() / "run.csv", json = tmp.path() / "run.json";
    runs.push_back(RepeatColumnsButTheTime(tmp.path() / "map", 59, flags, csv, json));
    ASSERT_FALSE(runs.back().empty());
    std::ifstream in(json);
    nlohmann::json frames = nlohmann::json::parse(in).at("frames");
    for (nlohmann::json& frame : frames) frame.erase("seconds");
    json_frames.push_back(std::move(frames));
  }
  ASSERT_EQ(runs[0].at("status").size(), 60u);
  EXPECT_GT(runs[0].size(), 40u);
  for (size_t r = 1; r < runs.size(); ++r) {
    for (const auto& [name, cells] : runs[0]) EXPECT_EQ(cells, runs[r].at(name)) << "run " << r << ": " << name;
    ASSERT_EQ(json_frames[0].size(), json_frames[r].size());
    for (size_t f = 0; f < json_frames[0].size(); ++f) {
      EXPECT_EQ(json_frames[0][f], json_frames[r][f]) << "run " << r << ", frame " << f;
    }
  }
}

// The verifier's seed in the frames' comparisons (--verifier-seed; default: the map's, as map.json records it): the
// map's seed given explicitly localizes as the default, every CSV column but the time the same; another seed draws
// other samples, and ORB's corridor comparisons (a third of ~54 matches inliers) verify other matches somewhere.
TEST(LocalizeCli, TheVerifiersSeedIsTheMapsUnlessAnotherIsGiven) {
  const fs::path data = Shared() / "data/corridor_conditions";
  if (Shared().empty() || !fs::exists(data)) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(data / "teach") + " -q -o " + Quote(tmp.path() / "map"), &out), 0) << out;
  std::ifstream map_json(tmp.path() / "map" / "map.json");
  const int map_seed = nlohmann::json::parse(map_json).at("options").at("verifier").at("seed").get<int>();
  // Per run, each CSV column but the time, by name, and the verifier's seed the run records.
  std::vector<std::map<std::string, std::vector<std::string>>> runs;
  std::vector<int> recorded_seeds;
  for (const std::string& flags : {std::string(), " --verifier-seed " + std::to_string(map_seed),
                                   " --verifier-seed " + std::to_string(map_seed + 1)}) {
    const fs::path csv = tmp.path() / "run.csv", json = tmp.path() / "run.json";
    runs.push_back(RepeatColumnsButTheTime(tmp.path() / "map", 9, flags, csv, json));
    ASSERT_FALSE(runs.back().empty());
    std::ifstream in(json);
    recorded_seeds.push_back(nlohmann::json::parse(in).at("options").at("verifier").at("seed").get<int>());
  }
  ASSERT_EQ(runs[0].at("status").size(), 10u);
  for (const auto& [name, cells] : runs[0]) EXPECT_EQ(cells, runs[1].at(name)) << "the map's seed given: " << name;
  EXPECT_NE(runs[0].at("verified"), runs[2].at("verified")) << "another seed verified the same matches everywhere";
  EXPECT_EQ(recorded_seeds, (std::vector<int>{map_seed, map_seed, map_seed + 1}));
}

}  // namespace
}  // namespace vmap
