// vmap simulate: teaches a route in a simulated corridor and repeats it from random offsets with vmap's localizer
// and route controller in the loop (pipelines/simulate_pipeline.h); prints the summary.

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/cli/other_matcher_flags.h"
#include "vmap/core/progress.h"
#include "vmap/pipelines/simulate_pipeline.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct SimulateFlags {
  SimulatePipelineOptions options;
  OptionFlags option_flags;
};

std::string Percent(double share) { return fmt::format("{:.1f}%", 100.0 * share); }

void RunSimulate(const SimulateFlags& flags) {
  ProgressOptions progress_options;
  progress_options.enabled = spdlog::should_log(spdlog::level::info);
  ProgressLine progress("simulate", flags.options.simulation.trials, "trials", progress_options);
  long done = 0;
  const SimulationResult result =
      RunSimulatePipeline(flags.options, [&](const TrialResult&) { progress.Update(++done); }).simulation;
  progress.Finish();

  const SimulationSummary& s = result.summary;
  std::cout << fmt::format("route           {} ({:.1f} m{})\n", result.route.name, result.route.path.length(),
                           result.route.corridor.closed() ? ", closed corridor" : "")
            << fmt::format("teach run       {} frames, {} key images ({}), {:.1f} s\n", result.teach_frames,
                           result.key_images, result.matcher, result.teach_seconds)
            << fmt::format("law             {}\n", ControlLawName(flags.options.simulation.controller.law))
            << fmt::format("reached goal    {} of {} ({}) within {} m\n", s.successes, s.trials,
                           Percent(s.success_rate), flags.options.simulation.goal_tolerance)
            << fmt::format("final error     {:.3f} m mean\n", s.mean_final_error)
            << (std::isnan(s.mean_lateral_rms_second_half)
                    ? std::string("lateral error   second half: no trial has samples past half the route\n")
                    : fmt::format("lateral error   second half: RMS {:.3f} m mean, {:.3f} m worst; {} of trials <= "
                                  "0.1 m\n",
                                  s.mean_lateral_rms_second_half, s.worst_lateral_rms_second_half,
                                  Percent(s.share_converged)))
            << fmt::format("frames lost     {} of {}\n", s.frames_lost, s.frames)
            << fmt::format("control step    {:.1f} ms mean, {:.1f} ms max (features, localization, control)\n",
                           1e3 * s.mean_step_seconds, 1e3 * s.max_step_seconds)
            << fmt::format("rendering       {:.0f} frames/s\n", s.render_frames_per_second)
            << fmt::format("time            {:.1f} s\n", result.seconds);
  const SimulatePipelineOptions& o = flags.options;
  if (!o.map.empty()) std::cout << "map             " << o.map << "\n";
  if (!o.json.empty()) std::cout << "json            " << o.json << "\n";
  if (!o.report.empty()) std::cout << "report          " << (fs::path(o.report) / "report.html").string() << "\n";
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto flags = std::make_shared<SimulateFlags>();
  CLI::App* command = app.add_subcommand(
      "simulate",
      "Teach a route in a simulated corridor and repeat it from random offsets, vmap's localizer and controller in "
      "the loop");
  AddOptionFlags(command, flags->options, flags->option_flags);
  command->callback([flags] {
    flags->option_flags.Run([&] {
      flags->options.Check();  // a value out of range is said first
      RefuseOtherMatchersFlags(flags->option_flags, flags->options.matcher.type);
      RunSimulate(*flags);
    });
  });
}

}  // namespace vmap::cli
