// The closed loop on every commit: a short straight route taught in the simulator, repeated from offsets with
// vmap's localizer and the route controller; the robot must stop at the goal and converge onto the path.

#include "vmap/pipelines/simulate_pipeline.h"

#include <unistd.h>

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "vmap/pipelines/localize_odometry.h"
#include "vmap/sources/odometry.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {

SimulatePipelineOptions StraightRoute(const std::filesystem::path& directory, double length) {
  const std::filesystem::path csv = directory / "route.csv";
  std::ofstream(csv) << "x,y\n0,0\n" << length << ",0\n";
  SimulatePipelineOptions pipeline;
  SimulationOptions& options = pipeline.simulation;
  options.route = csv.string();
  options.trials = 2;
  options.seed = 3;
  options.teach_speed = 0.4;
  options.threads = 2;
  return pipeline;
}

TEST(ClosedLoop, AShortStraightRouteIsRepeatedFromOffsetsToTheGoal) {
  testing::ScopedTempDir temp("closed_loop");
  SimulatePipelineOptions pipeline = StraightRoute(temp.path(), 6.0);
  pipeline.map = (temp.path() / "map").string();
  const SimulationOptions& options = pipeline.simulation;
  const SimulationResult result = RunSimulatePipeline(pipeline).simulation;
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
  EXPECT_TRUE(std::filesystem::is_regular_file(temp.path() / "map" / "map.json"));  // kept, as asked
  // With its teach odometry, as a robot's teach run keeps it: a repeat on the kept map has the taught profile.
  const std::vector<OdometrySample> odometry = ReadOdometryCsv(temp.path() / "map" / kTeachOdometryFileName);
  ASSERT_GE(odometry.size(), 2u);
  EXPECT_NEAR(odometry.back().x - odometry.front().x, 6.0, 0.5);  // the 6 m straight route
}

TEST(ClosedLoop, TheSameOptionsGiveTheSameRuns) {
  testing::ScopedTempDir temp("closed_loop_same");
  SimulatePipelineOptions pipeline = StraightRoute(temp.path(), 3.0);
  SimulationOptions& options = pipeline.simulation;
  options.camera.width = 320;  // a quarter of the pixels: only the sameness is checked
  options.camera.height = 240;
  options.trials = 1;
  options.threads = 1;
  options.max_lateral_offset = 0.3;
  SimulationResult runs[2];
  for (int run = 0; run < 2; ++run) runs[run] = RunSimulatePipeline(pipeline).simulation;
  ASSERT_EQ(runs[0].trials[0].samples.size(), runs[1].trials[0].samples.size());
  EXPECT_EQ(runs[0].trials[0].samples.back().pose.x, runs[1].trials[0].samples.back().pose.x);
  EXPECT_EQ(runs[0].trials[0].samples.back().pose.y, runs[1].trials[0].samples.back().pose.y);
  // Without options.map the maps were built in temporary folders, gone with the runs.
  const std::string own_prefix = "vmap-simulate-map-" + std::to_string(::getpid()) + "-";
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path())) {
    EXPECT_NE(entry.path().filename().string().rfind(own_prefix, 0), 0u) << entry.path();
  }
}

// The localizer's options reach every trial's localizer through the options struct (PrepareTrials: the session's
// options, following the map), as `vmap localize` hands them on. The two XFeat rules of main 8d40433 were told apart
// in the simulator across seasons so (docs/measurements/localization-conditions.md, "The simulator across seasons:
// which rule reaches it"): --no-rank-by-standout gave back main c56a22f's runs in every sample,
// --scene-change-log10-nfa 0 changed none. The flags themselves: OptionFlags.TheSimulatorTakesTheLocalizersFlags.
TEST(ClosedLoop, TheLocalizersOptionsReachEveryTrialsLocalizer) {
  testing::ScopedTempDir temp("closed_loop_options");
  SimulatePipelineOptions pipeline = StraightRoute(temp.path(), 3.0);
  pipeline.simulation.camera.width = 320;  // a quarter of the pixels: only the options are checked
  pipeline.simulation.camera.height = 240;
  LocalizerOptions& given = pipeline.simulation.localizer;
  given.rank_by_standout = false;
  given.scene_change_log10_nfa = -40.0;
  given.scene_change_tracked_log10_nfa = -500.0;
  given.relocalization_candidates = 7;
  const std::unique_ptr<PreparedTrials> prepared =
      PrepareTrials(pipeline.simulation, pipeline.matcher, temp.path() / "map");
  const LocalizerOptions& localizer = prepared->context.localizer;
  EXPECT_FALSE(localizer.rank_by_standout);
  EXPECT_EQ(localizer.scene_change_log10_nfa, -40.0);
  EXPECT_EQ(localizer.scene_change_tracked_log10_nfa, -500.0);
  EXPECT_EQ(localizer.relocalization_candidates, 7);
  EXPECT_EQ(localizer.route, prepared->context.taught.keys);  // the taught route, whatever was given
}

}  // namespace
}  // namespace vmap
