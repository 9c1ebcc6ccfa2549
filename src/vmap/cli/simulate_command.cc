// vmap simulate: teaches a route in a simulated corridor and repeats it from random offsets with vmap's localizer
// and route controller in the loop (simulation/closed_loop.h).

#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/progress.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/simulation/closed_loop.h"
#include "vmap/simulation/simulation_output.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct SimulateFlags {
  SimulationOptions options;
  MatcherOptions matcher;
  std::string json;
  std::string report;
  std::string map;
  OptionFlags option_flags;
};

// A report folder vmap simulate wrote: report.html and top_view.png, nothing else.
std::string WhyNotASimulationReport(const fs::path& directory) {
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
    const std::string name = entry.path().filename().string();
    if (name != "report.html" && name != "top_view.png")
      return "it holds '" + name + "', which vmap simulate never writes";
  }
  return ec ? "it cannot be listed: " + ec.message() : "";
}

std::string Percent(double share) { return fmt::format("{:.1f}%", 100.0 * share); }

void RunSimulate(const SimulateFlags& flags) {
  // Refusals first: options, outputs; the route and textures are read by Simulate before it writes anything.
  flags.options.Check();
  flags.matcher.Check();
  std::vector<std::vector<OutputInput>> inputs = {NamedInput(flags.options.teach_textures, "--teach-textures"),
                                                  NamedInput(flags.options.repeat_textures, "--repeat-textures")};
  if (FindEnum(kRouteShapeNames, flags.options.route) == std::nullopt)
    inputs.push_back(NamedInput(flags.options.route, "--route"));
  CheckOutputs({{flags.json, "--json"}}, inputs);
  OutputPolicy report_policy;
  report_policy.why_not_ours = WhyNotASimulationReport;
  report_policy.kind = "a vmap simulate report";
  for (const std::string& path : {flags.options.teach_textures, flags.options.repeat_textures}) {
    if (!path.empty()) report_policy.inputs.push_back(path);
  }
  std::unique_ptr<AtomicOutputDirectory> report;
  if (!flags.report.empty()) report = std::make_unique<AtomicOutputDirectory>(flags.report, report_policy);
  // The map: kept with --map, otherwise built in a temporary folder that goes when the run ends.
  OutputPolicy map_policy;
  map_policy.why_not_ours = WhyNotAVmapMap;
  map_policy.kind = "a vmap map";
  map_policy.inputs = report_policy.inputs;
  const fs::path map_path = flags.map.empty()
                                ? fs::temp_directory_path() / fmt::format("vmap-simulate-map-{}", ::getpid())
                                : fs::path(flags.map);
  AtomicOutputDirectory map_directory(map_path, map_policy);

  ProgressOptions progress_options;
  progress_options.enabled = spdlog::should_log(spdlog::level::info);
  ProgressLine progress("simulate", flags.options.trials, "trials", progress_options);
  long done = 0;
  const SimulationResult result = Simulate(flags.options, flags.matcher, map_directory.path(),
                                           [&](const TrialResult&) { progress.Update(++done); });
  progress.Finish();
  if (!flags.map.empty()) map_directory.Commit();
  if (report) {
    WriteSimulationReport(result, flags.options, report->path());
    report->Commit();
  }
  if (!flags.json.empty()) WriteFileAtomically(flags.json, SimulationJson(result, flags.options).dump() + "\n");

  const SimulationSummary& s = result.summary;
  std::cout << fmt::format("route           {} ({:.1f} m{})\n", result.route.name, result.route.path.length(),
                           result.route.corridor.closed() ? ", closed corridor" : "")
            << fmt::format("teach run       {} frames, {} key images ({}), {:.1f} s\n", result.teach_frames,
                           result.key_images, result.matcher, result.teach_seconds)
            << fmt::format("law             {}\n", ControlLawName(flags.options.controller.law))
            << fmt::format("reached goal    {} of {} ({}) within {} m\n", s.successes, s.trials,
                           Percent(s.success_rate), flags.options.goal_tolerance)
            << fmt::format("final error     {:.3f} m mean\n", s.mean_final_error)
            << fmt::format("lateral error   second half: RMS {:.3f} m mean, {:.3f} m worst; {} of trials <= 0.1 m\n",
                           s.mean_lateral_rms_second_half, s.worst_lateral_rms_second_half, Percent(s.share_converged))
            << fmt::format("frames lost     {} of {}\n", s.frames_lost, s.frames)
            << fmt::format("control step    {:.1f} ms mean, {:.1f} ms max (features, localization, control)\n",
                           1e3 * s.mean_step_seconds, 1e3 * s.max_step_seconds)
            << fmt::format("rendering       {:.0f} frames/s\n", s.render_frames_per_second)
            << fmt::format("time            {:.1f} s\n", result.seconds);
  if (!flags.map.empty()) std::cout << "map             " << flags.map << "\n";
  if (!flags.json.empty()) std::cout << "json            " << flags.json << "\n";
  if (report) std::cout << "report          " << (fs::path(flags.report) / "report.html").string() << "\n";
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto flags = std::make_shared<SimulateFlags>();
  CLI::App* command = app.add_subcommand(
      "simulate",
      "Teach a route in a simulated corridor and repeat it from random offsets, vmap's localizer and controller in "
      "the loop");
  AddOptionFlags(command, flags->options, flags->option_flags);
  AddOptionFlags(command, flags->matcher, flags->option_flags);
  command->add_option("--json", flags->json, "Write the run (options, summary, every trial) to this JSON file");
  command->add_option("--report", flags->report, "Write an HTML report of the run into this directory");
  command->add_option("--map", flags->map, "Keep the teach run's map in this directory");
  command->callback([flags] { flags->option_flags.Run([&] { RunSimulate(*flags); }); });
}

}  // namespace vmap::cli
