#pragma once
// The simulate pipeline: stage 4 proved in simulation. A route is taught in a textured corridor (its rendered
// frames built into a map by the build pipeline, as `vmap build` builds one), then repeated N times from random
// offsets with the localization session's localizer and the route controller in the loop; each repeat is measured
// against the taught path. What `vmap simulate` runs; the ROS simulator node takes its set-up (PrepareTrials) and
// steps a trial from outside (simulation/trial_run.h).
//
//   SimulatePipelineOptions options;  options.simulation.route = "turn";  options.simulation.trials = 50;
//   SimulatePipelineResult result = RunSimulatePipeline(options);
//   result.simulation.summary.success_rate ...
//
// Docs: docs/drive.md.

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/pipelines/localize_pipeline.h"
#include "vmap/simulation/closed_loop.h"
#include "vmap/simulation/corridor_world.h"
#include "vmap/simulation/simulation_options.h"

namespace vmap {

struct SimulatePipelineOptions {
  SimulationOptions simulation;
  MatcherOptions matcher;  // the teach run's map is built, and the repeats localized, with it
  std::string map;         // keep the teach run's map in this folder; "" = built in a temporary one, removed
  std::string json;        // the run (options, summary, every trial); "" = none
  std::string report;      // a folder for the HTML report; "" = none
  // Not an option (no flag, no JSON): called after each rendered frame, of the teach run and of every trial, from
  // the thread that rendered it. It may throw to stop the run (a host's Ctrl-C); nothing is written then.
  std::function<void()> after_frame;

  // The fields above, each once: the simulation's, the matchers', --map, --json, --report.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// What every trial of a simulation shares, made once: the route and its worlds, the teach run and its map (built
// into a directory), the map opened for localization, and the trials' context, which points into the rest: keep
// it where PrepareTrials put it.
struct PreparedTrials {
  SimulatedRoute route;
  std::optional<CorridorWorld> teach_world;
  std::optional<CorridorWorld> repeat_world;  // the teach world's panels with the repeat textures, if any
  std::unique_ptr<LocalizationSession> session;
  int teach_frames = 0;
  double teach_seconds = 0.0;                  // rendering the teach run and building its map
  std::vector<OdometrySample> teach_odometry;  // the teach run's, exact (the taught profile's source)
  TrialContext context;                        // for RunTrial, or a TrialRun stepped from outside (trial_run.h)

  const LocalizationMap& map() const { return session->opened(); }
};

// Stages 1-4 of RunSimulatePipeline: checks the options, reads the route and the textures, builds the worlds,
// teaches the route (RunBuildPipeline into `map_directory`: absent, empty or a vmap map, replaced) and opens the
// map (a LocalizationSession). Throws InputError (OptionError for an option) before any work. `after_frame`
// (optional) as SimulatePipelineOptions::after_frame, also kept in the trials' context.
std::unique_ptr<PreparedTrials> PrepareTrials(const SimulationOptions& options, const MatcherOptions& matcher,
                                              const std::filesystem::path& map_directory,
                                              const std::function<void()>& after_frame = {});

struct SimulatePipelineResult {
  SimulationResult simulation;
};

// Stage 1 of RunSimulatePipeline, for hosts that run the stages themselves (the ROS simulator node): checks the
// options, that no output (json, map, report) may replace what the run reads (the route, the textures) or another
// output, and that the map's folder is absent, empty or a vmap map. Throws OptionError naming the field, or
// InputError for the map's folder.
void CheckSimulateOutputs(const SimulatePipelineOptions& options);

// Teaches and repeats, stages in order:
//   1. check the options and the outputs (none may overwrite the route, the textures or each other);
//   2. claim the report and map folders (a temporary map folder without options.map), before any work;
//   3. read the route and the textures, build the worlds;
//   4. the teach run: render it, build its map (the build pipeline), open the map (a localization session);
//   5. the trials, on options.simulation.threads threads;
//   6. write the JSON and the report, keep the map when asked.
// `on_trial` (optional) is called after each trial, from the thread that ran it, under a lock. Nothing is
// written when it throws.
SimulatePipelineResult RunSimulatePipeline(const SimulatePipelineOptions& options,
                                           const std::function<void(const TrialResult&)>& on_trial = {});

}  // namespace vmap
