// `vmap simulate` as a user runs it: a short run that writes its JSON and report, and every kind of bad input
// answered with one error line, status 2 and nothing written.

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
using ::vmap::testing::Quote;
using ::vmap::testing::RunVmap;
namespace {

fs::path WriteRoute(const fs::path& directory, const std::string& text) {
  const fs::path path = directory / "route.csv";
  std::ofstream(path) << text;
  return path;
}

TEST(SimulateCli, RunsTrialsAndWritesItsJsonAndReport) {
  ::vmap::testing::ScopedTempDir temp("simulate_cli");
  const fs::path route = WriteRoute(temp.path(), "0,0\n4,0\n");
  const fs::path json = temp.path() / "run.json", report = temp.path() / "report", map = temp.path() / "map";
  std::string out;
  // A quarter of the pixels: whether the robot converges is the closed-loop test's (closed_loop_test.cc).
  ASSERT_EQ(RunVmap("simulate --route " + Quote(route) +
                        " --trials 1 --camera-width 320 --camera-height 240 "
                        "--lateral-offset 0.3 --time-limit 1 --json " +
                        Quote(json) + " --report " + Quote(report) + " --map " + Quote(map) + " -q",
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("reached goal    "), std::string::npos) << out;
  std::ifstream in(json);
  const nlohmann::json run = nlohmann::json::parse(in);
  EXPECT_EQ(run["summary"]["trials"], 1);
  EXPECT_FALSE(run["trials"][0]["end"].get<std::string>().empty());
  EXPECT_EQ(run["options"]["max_lateral_offset"], 0.3);
  EXPECT_FALSE(run["trials"][0]["samples"]["x"].empty());
  EXPECT_TRUE(fs::is_regular_file(report / "report.html"));
  EXPECT_TRUE(fs::is_regular_file(report / "top_view.png"));
  EXPECT_TRUE(fs::is_regular_file(map / "map.json"));
}

// Runs `vmap simulate ARGS --json J --report R` expecting a refusal: one `vmap: error:` line naming `expected`,
// status 2, neither output written.
void ExpectRefused(const std::string& arguments, const std::string& expected) {
  ::vmap::testing::ScopedTempDir temp("simulate_refused");
  const fs::path json = temp.path() / "run.json", report = temp.path() / "report";
  std::string out;
  EXPECT_EQ(RunVmap("simulate " + arguments + " --trials 1 --json " + Quote(json) + " --report " + Quote(report), &out),
            2)
      << arguments << "\n"
      << out;
  EXPECT_EQ(out.rfind("vmap: error: ", 0), 0u) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_NE(out.find(expected), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(json));
  EXPECT_FALSE(fs::exists(report));
}

TEST(SimulateCli, BadInputIsOneErrorLineAndWritesNothing) {
  ::vmap::testing::ScopedTempDir temp("simulate_bad");
  ExpectRefused("--route " + Quote(WriteRoute(temp.path(), "0,0\n3,oops\n")), "line 2");
  ExpectRefused("--route " + Quote(WriteRoute(temp.path(), "0,0\n10,0\n10,10\n5,10\n5,-10\n")), "comes back within");
  ExpectRefused("--route " + Quote(temp.path() / "missing.csv"), "missing.csv");
  ExpectRefused("--route zigzag", "zigzag");
  const fs::path textures = temp.path() / "textures";
  fs::create_directory(textures);
  std::ofstream(textures / "wall.png") << "this is not a PNG";
  ExpectRefused("--teach-textures " + Quote(textures), "wall.png");
  ExpectRefused("--lateral-offset 1.5", "--lateral-offset");
  ExpectRefused("--lateral-offset nan", "--lateral-offset");
  ExpectRefused("--speed nan", "--speed");
  ExpectRefused("--heading-gain -1", "--heading-gain");
  ExpectRefused("--rate inf", "--rate");
  ExpectRefused("--law pid", "pid");
  // A robot as wide as the corridor is named as the radius (the offset was blamed, told to be at most -3.50 m).
  ExpectRefused("--robot-radius 1.5 --lateral-offset 0", "--robot-radius 1.5 m makes the robot 3 m wide");
  // Hexadecimal is no number of metres (strtod read 0x4 as 4).
  ExpectRefused("--route " + Quote(WriteRoute(temp.path(), "0,0\n0x4,0\n")), "line 2");
}

// Outputs that would land on each other are refused before the teach run: each was once found written over
// (the JSON as the map's map.json, the JSON inside the report) or refused only after all the trials.
TEST(SimulateCli, OutputsThatWouldLandOnEachOtherAreRefusedBeforeAnyWork) {
  ::vmap::testing::ScopedTempDir temp("simulate_outputs");
  const fs::path route = WriteRoute(temp.path(), "0,0\n4,0\n");
  const fs::path map = temp.path() / "map", report = temp.path() / "report";
  fs::create_directory(map);
  fs::create_directory(report);
  struct Case {
    std::string outputs, expected;
  };
  const Case cases[] = {
      {"--map " + Quote(map) + " --json " + Quote(map / "map.json"), "would overwrite the map's map.json"},
      {"--report " + Quote(report) + " --json " + Quote(report / "report.html"), "lies inside the report folder"},
      {"--report " + Quote(report) + " --map " + Quote(report / "map"), "lie one in the other"},
      {"--map " + Quote(map) + " --report " + Quote(map / "report"), "lie one in the other"},
      {"--map " + Quote(map) + " --report " + Quote(map.string() + "/"), "lie one in the other"},
  };
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(RunVmap("simulate --route " + Quote(route) + " --trials 1 " + c.outputs, &out), 2) << c.outputs;
    EXPECT_EQ(out.rfind("vmap: error: ", 0), 0u) << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << out;
    EXPECT_TRUE(fs::is_empty(map)) << c.outputs;
    EXPECT_TRUE(fs::is_empty(report)) << c.outputs;
  }
  // The map's folder may not hold the route it teaches: replaced, it would take the route with it.
  const fs::path kept = temp.path() / "kept";
  fs::create_directory(kept);
  const fs::path inside = WriteRoute(kept, "0,0\n4,0\n");
  std::string out;
  EXPECT_EQ(RunVmap("simulate --route " + Quote(inside) + " --trials 1 --map " + Quote(kept), &out), 2) << out;
  EXPECT_NE(out.find("is or holds the input"), std::string::npos) << out;
  EXPECT_TRUE(fs::is_regular_file(inside));
}

}  // namespace
}  // namespace vmap
