// `vmap simulate` as a user runs it: a short run that writes its JSON and report, and every kind of bad input
// answered with one error line, status 2 and nothing written.

#include <cmath>
#include <fstream>
#include <vector>

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

// Each trial's end, final error and last sample's pose (x, y, lateral) of `vmap simulate ARGS --json`.
struct TrialEnd {
  std::string end;
  double final_error = 0.0;
  double x = 0.0, y = 0.0, lateral = 0.0;
};
std::vector<TrialEnd> SimulateTrials(const std::string& arguments) {
  ::vmap::testing::ScopedTempDir temp("simulate_end");
  const fs::path json = temp.path() / "run.json";
  std::string out;
  EXPECT_EQ(
      RunVmap("simulate " + arguments + " --camera-width 160 --camera-height 120 --threads 1 -q --json " + Quote(json),
              &out),
      0)
      << out;
  std::ifstream in(json);
  const nlohmann::json run = nlohmann::json::parse(in);
  std::vector<TrialEnd> ends;
  for (const nlohmann::json& trial : run["trials"]) {
    const nlohmann::json& samples = trial["samples"];
    ends.push_back(
        {trial["end"], trial["final_error_m"], samples["x"].back(), samples["y"].back(), samples["lateral"].back()});
  }
  return ends;
}

// Where the robot is is searched along the corridor within what a step can drive, and all round a closed one: a robot
// driving 3 m a step "left the corridor" at its first (searched within 2 m ahead), and one on a CSV loop's last side
// did too (its closing segment was not searched).
TEST(SimulateCli, ARobotOnTheCentreLineStaysInTheCorridor) {
  ::vmap::testing::ScopedTempDir temp("simulate_centre");
  const std::string exact = " --trials 1 --lateral-offset 0 --heading-offset 0 --speed-noise 0 --turn-noise 0";
  const TrialEnd fast = SimulateTrials(exact + " --rate 1 --teach-speed 3 --max-speed 4 --max-acceleration 100").at(0);
  EXPECT_EQ(fast.end, "reached goal") << "at " << fast.x << ", " << fast.y;
  const fs::path square = WriteRoute(temp.path(), "x,y\n0,0\n6,0\n6,6\n0,6\n0,0\n");
  const TrialEnd loop = SimulateTrials(exact + " --route " + Quote(square)).at(0);
  EXPECT_EQ(loop.end, "reached goal") << "at " << loop.x << ", " << loop.y;
}

// A trial that ends between frames (the robot left the corridor) records where it ended: its last sample is the pose
// final_error measures, outside the corridor, not the frame's before it (0.03 m short at the default speed and rate).
TEST(SimulateCli, TheLastSampleIsWhereTheTrialEnded) {
  int left = 0;
  for (const TrialEnd& trial : SimulateTrials(
           " --trials 4 --corridor-width 1.0 --robot-radius 0.42 --lateral-offset 0.05 --heading-offset 45")) {
    if (trial.end != "left the corridor") continue;
    ++left;
    EXPECT_GE(std::abs(trial.lateral), 0.08 - 0.0005) << "the room either side of the centre line, to the JSON's mm";
    EXPECT_NEAR(std::hypot(trial.x - 10.0, trial.y), trial.final_error, 0.005);  // the straight route's goal: (10, 0)
  }
  EXPECT_GE(left, 1) << "no trial left the corridor: the test no longer reaches its case";
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
