// vmap eval MAP_DIR [--gt FILE]: the evaluation pipeline (pipelines/eval_pipeline.h), its table and summary.

#include <iostream>
#include <memory>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/core/output_file.h"
#include "vmap/pipelines/eval_pipeline.h"
#include "vmap/report/evaluation_summary.h"

namespace vmap::cli {

namespace {

struct EvalCommand {
  EvalPipelineOptions options;
  bool table = true;
  OptionFlags flags;
};

void RunEval(const EvalCommand& command) {
  const EvalPipelineResult result = RunEvalPipeline(command.options);
  if (command.table) std::cout << FormatEvaluationTable(result.evaluation) << "\n";
  std::cout << FormatEvaluationSummary(result.evaluation);
  if (!result.saved_to.empty()) std::cout << "written to      " << result.saved_to << "\n";
  // --json naming the map's own eval.json is that file, written once (RunEvalPipeline).
  if (!command.options.json.empty() && !SameOutput(command.options.json, result.saved_to)) {
    std::cout << "written to      " << command.options.json << "\n";
  }
}

}  // namespace

void AddEvalCommand(CLI::App& app) {
  auto state = std::make_shared<EvalCommand>();
  CLI::App* command = app.add_subcommand(
      "eval", "Check every link of a map against ground-truth camera poses (rotation, translation, epipolar errors)");
  AddOptionFlags(command, state->options, state->flags);
  command->add_flag("!--no-table", state->table, "Print only the summary, not one row per link");
  command->callback([state] { state->flags.Run([&] { RunEval(*state); }); });
}

}  // namespace vmap::cli
