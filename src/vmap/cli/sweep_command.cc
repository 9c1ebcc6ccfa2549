// vmap sweep INPUT --thresholds 0.1:0.9:0.1: the sweep pipeline (pipelines/sweep_pipeline.h), the paper's table.

#include <iostream>
#include <memory>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/cli/other_matcher_flags.h"
#include "vmap/pipelines/sweep_pipeline.h"
#include "vmap/report/summary.h"

namespace vmap::cli {

namespace {

struct SweepCommand {
  SweepPipelineOptions options;
  OptionFlags flags;
};

void RunSweep(const SweepCommand& command) {
  const SweepResult sweep = RunSweepPipeline(command.options);
  std::cout << SweepToMarkdown(sweep);
  if (!command.options.output.empty()) {
    std::cout << "\nwritten to " << command.options.output << " (sweep.md, sweep.csv, sweep.json)\n";
  }
  // A report in a folder of its own: said as the output is.
  if (!command.options.report.empty() && command.options.report != command.options.output) {
    std::cout << (command.options.output.empty() ? "\n" : "") << "report written to " << command.options.report
              << " (report.html)\n";
  }
}

}  // namespace

void AddSweepCommand(CLI::App& app) {
  auto state = std::make_shared<SweepCommand>();
  CLI::App* command =
      app.add_subcommand("sweep", "Build maps for a range of thresholds tau in one pass (the paper's tables)");
  SweepPipelineOptions& options = state->options;
  AddOptionFlags(command, options, state->flags);
  // --gt with a FILE or none: evaluate against that file, or the input's own ground truth.
  CLI::Option* gt = state->flags
                        .AddOption(command, "--gt", options.gt.path, "gt.path",
                                   "Add a usable-links column (see `vmap eval`): with no FILE, the input's own "
                                   "ground truth; or a kitti, tum or euroc poses file")
                        ->expected(0, 1)
                        ->group(kGroundTruthSection);
  command->callback([state, gt] {
    state->options.evaluate = gt->count() > 0;
    state->flags.Run([&] {
      state->options.Check();  // a value out of range is said first
      RefuseOtherMatchersFlags(state->flags, state->options.matcher.type);
      RunSweep(*state);
    });
  });
}

}  // namespace vmap::cli
