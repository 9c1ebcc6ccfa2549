#pragma once
// The closed-loop simulator's trials and what they add up to: a route taught in a textured corridor is repeated N
// times from random offsets with vmap's localizer and route controller in the loop, and each repeat is measured
// against the taught path. The whole run (teach, map, trials, outputs) is the simulate pipeline
// (pipelines/simulate_pipeline.h), which `vmap simulate` and the ROS simulator node call.
//
// Docs: docs/drive.md.

#include <functional>
#include <string>
#include <vector>

#include "vmap/simulation/repeat_trial.h"
#include "vmap/simulation/route_path.h"
#include "vmap/simulation/simulation_options.h"

namespace vmap {

struct SimulationSummary {
  int trials = 0;
  int successes = 0;  // stopped at the goal within goal_tolerance
  double success_rate = 0.0;
  double mean_final_error = 0.0;  // m, over all trials
  // m, over trials that reached the second half; NaN when none did (a route too short to have samples past it)
  double mean_lateral_rms_second_half = 0.0;
  double worst_lateral_rms_second_half = 0.0;  // m; NaN when no trial reached the second half
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

// The trials 0..count-1 of `context`, independent of each other (each its own localizer, controller and robot),
// on `threads` threads (0 = one per core). `on_trial` (optional) is called after each trial, from the thread that
// ran it, under a lock.
std::vector<TrialResult> RunTrials(const TrialContext& context, int count, int threads,
                                   const std::function<void(const TrialResult&)>& on_trial = {});

SimulationSummary Summarize(const std::vector<TrialResult>& trials);

}  // namespace vmap
