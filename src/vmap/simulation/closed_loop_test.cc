// The closed loop on every commit: a short straight route taught in the simulator, repeated from offsets with
// vmap's localizer and the route controller; the robot must stop at the goal and converge onto the path.

#include "vmap/simulation/closed_loop.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {

SimulationOptions StraightRoute(const std::filesystem::path& directory, double length) {
  const std::filesystem::path csv = directory / "route.csv";
  std::ofstream(csv) << "x,y\n0,0\n" << length << ",0\n";
  SimulationOptions options;
  options.route = csv.string();
  options.trials = 2;
  options.seed = 3;
  options.teach_speed = 0.4;
  options.threads = 2;
  return options;
}

TEST(ClosedLoop, AShortStraightRouteIsRepeatedFromOffsetsToTheGoal) {
  testing::ScopedTempDir temp("closed_loop");
  const SimulationOptions options = StraightRoute(temp.path(), 6.0);
  std::filesystem::create_directory(temp.path() / "map");
  const SimulationResult result = Simulate(options, MatcherOptions{}, temp.path() / "map");
  EXPECT_GE(result.key_images, 3);
  ASSERT_EQ(result.trials.size(), 2u);
  for (const TrialResult& trial : result.trials) {
    SCOPED_TRACE("trial " + std::to_string(trial.index));
    EXPECT_GT(std::abs(trial.start_lateral), 0.05);  // the seed starts both off the path
    EXPECT_EQ(trial.end, "reached goal");
    EXPECT_TRUE(trial.success);
    EXPECT_LE(trial.final_error, options.goal_tolerance);
    EXPECT_LE(trial.lateral_rms_second_half, 0.1);
    ASSERT_FALSE(trial.samples.empty());
    // Converged: the last metres are nearer the path than the start was.
    EXPECT_LT(std::abs(trial.samples.back().lateral), std::abs(trial.start_lateral));
  }
  EXPECT_EQ(result.summary.successes, 2);
}

TEST(ClosedLoop, TheSameOptionsGiveTheSameRuns) {
  testing::ScopedTempDir temp("closed_loop_same");
  SimulationOptions options = StraightRoute(temp.path(), 3.0);
  options.camera.width = 320;  // a quarter of the pixels: only the sameness is checked
  options.camera.height = 240;
  options.trials = 1;
  options.threads = 1;
  options.max_lateral_offset = 0.3;
  SimulationResult runs[2];
  for (int run = 0; run < 2; ++run) {
    const auto map = temp.path() / ("map" + std::to_string(run));
    std::filesystem::create_directory(map);
    runs[run] = Simulate(options, MatcherOptions{}, map);
  }
  ASSERT_EQ(runs[0].trials[0].samples.size(), runs[1].trials[0].samples.size());
  EXPECT_EQ(runs[0].trials[0].samples.back().pose.x, runs[1].trials[0].samples.back().pose.x);
  EXPECT_EQ(runs[0].trials[0].samples.back().pose.y, runs[1].trials[0].samples.back().pose.y);
}

}  // namespace
}  // namespace vmap
