// vmap eval MAP_DIR [--gt FILE]: every link of a map against ground-truth camera poses.

#include <filesystem>
#include <iostream>
#include <memory>

#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/cli/option_flags.h"
#include "vmap/cli/output_files.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/evaluation/evaluation_inputs.h"
#include "vmap/evaluation/evaluation_json.h"
#include "vmap/evaluation/map_evaluation.h"
#include "vmap/map/map_io.h"
#include "vmap/report/evaluation_summary.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct EvalFlags {
  std::string map;
  std::string gt;
  std::string gt_format = "auto";
  std::string camera;
  std::string json;
  bool save = true;
  bool table = true;
  EvaluationOptions options;
  OptionFlags option_flags;
};

void RunEval(const EvalFlags& flags) {
  flags.options.Check();
  CheckOutputs(
      {{flags.json, "--json"}},
      {MapInputs(flags.map), NamedInput(flags.gt, "the ground truth"),
       fs::is_regular_file(flags.camera) ? NamedInput(flags.camera, "the --camera file") : std::vector<OutputInput>{}});
  ParseEvaluationCamera(flags.camera);  // a wrong --camera is refused first, even where the map's camera is used
  const VisualMap map = ReadMap(flags.map);
  const GroundTruth truth = MapGroundTruth(map, flags.gt, ParseGroundTruthFormat(flags.gt_format));
  const Camera camera = EvaluationCamera(map, flags.camera);
  MapEvaluation evaluation = EvaluateMap(map, truth, camera, flags.options);
  evaluation.map_path = flags.map;
  if (evaluation.summary.links > 0 && evaluation.summary.evaluated_links == 0) {
    // Ground truth of another sequence: an evaluation of nothing would replace eval.json all the same.
    throw InputError("the ground truth '" + truth.path + "' covers none of the map's " +
                     std::to_string(evaluation.summary.links) + " links (no pose for both key images of any)" +
                     "; give the ground truth of the map's input '" + map.input.path + "'" +
                     (truth.format == GroundTruthFormat::kKitti ? "" : " and check that the timestamps match"));
  }
  if (evaluation.summary.evaluated_links < evaluation.summary.links) {
    spdlog::warn("the ground truth covers {} of the map's {} links; the others are left out",
                 evaluation.summary.evaluated_links, evaluation.summary.links);
  }
  const std::string json = EvaluationToJson(evaluation);
  if (flags.save) WriteFileAtomically(fs::path(flags.map) / kEvaluationFileName, json);
  if (!flags.json.empty()) WriteFileAtomically(flags.json, json);
  if (flags.table) std::cout << FormatEvaluationTable(evaluation) << "\n";
  std::cout << FormatEvaluationSummary(evaluation);
  if (flags.save) std::cout << "written to      " << (fs::path(flags.map) / kEvaluationFileName).string() << "\n";
}

}  // namespace

void AddEvalCommand(CLI::App& app) {
  auto flags = std::make_shared<EvalFlags>();
  CLI::App* command = app.add_subcommand(
      "eval", "Check every link of a map against ground-truth camera poses (rotation, translation, epipolar errors)");
  command->add_option("map", flags->map, "Map directory written by `vmap build`")->required();
  OptionFlags& option_flags = flags->option_flags;
  // The ground truth and camera as MapGroundTruth and EvaluationCamera name them.
  option_flags.AddOption(command, "--gt", flags->gt, "gt.path",
                         "Ground-truth poses (default: the input's own: KITTI poses.txt, TUM groundtruth.txt, EuRoC "
                         "state_groundtruth_estimate0/data.csv). Formats: kitti, tum, euroc");
  option_flags
      .AddOption(command, "--gt-format", flags->gt_format, "gt.format",
                 "Format of --gt: " + ListEnumNames(kGroundTruthFormatNames) + " (auto: from its first line)")
      ->capture_default_str();
  option_flags.AddOption(
      command, "--camera", flags->camera, "camera",
      "Intrinsics when the map has none: fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]] or a calibration file");
  command->add_option("--json", flags->json, "Also write the evaluation (JSON) to this file");
  command->add_flag("!--no-save", flags->save, "Do not write eval.json into the map directory");
  command->add_flag("!--no-table", flags->table, "Print only the summary, not one row per link");
  AddOptionFlags(command, flags->options, option_flags);
  command->callback([flags] { flags->option_flags.Run([&] { RunEval(*flags); }); });
}

}  // namespace vmap::cli
