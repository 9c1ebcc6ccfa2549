#pragma once
// The closed-loop simulator (stage 4 proved in simulation): a route is taught in a textured corridor (rendered
// frames, vmap's normal build), then repeated N times from random offsets with vmap's localizer and route
// controller in the loop, and each repeat is measured against the taught path.
//
//   SimulationOptions options;  options.route = "turn";  options.trials = 50;
//   SimulationResult result = Simulate(options, MatcherOptions{}, map_directory);
//   result.summary.success_rate ...
//
// Docs: docs/drive.md. Front end: `vmap simulate` (cli/simulate_command.cc).

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vmap/features/matcher_registry.h"
#include "vmap/localization/localization_map.h"
#include "vmap/simulation/corridor_world.h"
#include "vmap/simulation/repeat_trial.h"
#include "vmap/simulation/route_path.h"
#include "vmap/simulation/simulation_options.h"

namespace vmap {

struct SimulationSummary {
  int trials = 0;
  int successes = 0;  // stopped at the goal within goal_tolerance
  double success_rate = 0.0;
  double mean_final_error = 0.0;               // m, over all trials
  double mean_lateral_rms_second_half = 0.0;   // m, over trials that reached the second half
  double worst_lateral_rms_second_half = 0.0;  // m
  double share_converged = 0.0;                // trials whose second-half lateral RMS is at most 0.1 m
  long frames = 0;
  long frames_lost = 0;
  double mean_step_seconds = 0.0;  // localization and control per frame (features included, rendering not)
  double max_step_seconds = 0.0;
  double render_frames_per_second = 0.0;  // rendering alone, per thread
};

struct SimulationResult {
  SimulatedRoute route;
  std::string matcher;  // the map's matcher
  int teach_frames = 0;
  int key_images = 0;
  std::vector<Pose2d> key_image_poses;  // where each key image was taken (teach run)
  double teach_seconds = 0.0;           // rendering and building the map
  std::vector<TrialResult> trials;
  SimulationSummary summary;
  double seconds = 0.0;  // wall time of the whole simulation
};

// The route options.route names: a built-in shape, or a CSV of waypoints; checked against the corridor. Throws
// InputError when it cannot be read or does not fit.
SimulatedRoute LoadSimulatedRoute(const SimulationOptions& options);

// What every trial of a simulation shares, made once (Simulate's stages 1-4): the route and its worlds, the teach
// run and its map (built into a directory), the map opened for localization, and the trials' context, which
// points into the rest: keep it where PrepareTrials put it.
struct PreparedTrials {
  SimulatedRoute route;
  std::optional<CorridorWorld> teach_world;
  std::optional<CorridorWorld> repeat_world;  // the teach world's panels with the repeat textures, if any
  LocalizationMap map;
  int teach_frames = 0;
  double teach_seconds = 0.0;
  std::vector<OdometrySample> teach_odometry;  // the teach run's, exact (the taught profile's source)
  TrialContext context;                        // for RunTrial, or a TrialRun stepped from outside (trial_run.h)
};

// Checks the options, builds the worlds, teaches the route (the map built with `matcher` into `map_directory`,
// which must exist and be empty) and opens the map. Throws as Simulate does, before any work.
std::unique_ptr<PreparedTrials> PrepareTrials(const SimulationOptions& options, const MatcherOptions& matcher,
                                              const std::filesystem::path& map_directory);

// Teaches and repeats. The map is built with `matcher` into `map_directory` (which must exist and be empty).
// Throws InputError (bad route or textures) and OptionError (options.Check()) before any work.
// `on_trial` (optional) is called after each trial, from the thread that ran it, under a lock.
SimulationResult Simulate(const SimulationOptions& options, const MatcherOptions& matcher,
                          const std::filesystem::path& map_directory,
                          const std::function<void(const TrialResult&)>& on_trial = {});

SimulationSummary Summarize(const std::vector<TrialResult>& trials);

}  // namespace vmap
