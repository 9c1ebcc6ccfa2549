// vmap report MAP_DIR | RUN.json: the report pipeline (pipelines/report_pipeline.h).

#include <iostream>
#include <memory>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/pipelines/report_pipeline.h"

namespace vmap::cli {

void AddReportCommand(CLI::App& app) {
  struct ReportCommand {
    ReportPipelineOptions options;
    OptionFlags flags;
  };
  auto state = std::make_shared<ReportCommand>();
  CLI::App* command = app.add_subcommand(
      "report",
      "Write report.html into a map directory: summary, key images, match figures and plots (offline "
      "page); or, given the --json file of `vmap localize`, the report of that localization run");
  AddOptionFlags(command, state->options, state->flags);
  command->callback([state] {
    state->flags.Run([&] {
      const std::string written = RunReportPipeline(state->options).string();  // nothing printed if it throws
      std::cout << "report          " << written << "\n";
    });
  });
}

}  // namespace vmap::cli
