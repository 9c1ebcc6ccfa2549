// vmap sweep INPUT --thresholds 0.1:0.9:0.1: the paper's table, every tau in one pass over the input.

#include <filesystem>
#include <iostream>
#include <optional>

#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/common_options.h"
#include "vmap/cli/map_options.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/evaluation/evaluation_inputs.h"
#include "vmap/evaluation/evaluation_json.h"
#include "vmap/evaluation/map_evaluation.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/sweep_thresholds.h"
#include "vmap/report/html_report.h"
#include "vmap/report/summary.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct SweepFlags {
  std::string input;
  std::string thresholds = "0.1:0.9:0.1";
  std::string output;
  bool write_maps = false;
  std::string report;
  SourceFlags source;
  MatcherOptions matcher;
  VerifierFlags verifier;
  KeyImageFlags key_images;
  bool evaluate = false;  // --gt given, with or without a file
  std::string gt;
  std::string gt_format = "auto";
  OptionFlags option_flags;
};

// Whether two output paths name the same folder (neither need exist yet).
bool SamePath(const std::string& a, const std::string& b) {
  std::error_code ec;
  return fs::weakly_canonical(fs::absolute(a), ec) == fs::weakly_canonical(fs::absolute(b), ec);
}

void RunSweep(const SweepFlags& flags) {
  const std::vector<double> taus = ParseThresholds(flags.thresholds);
  const FrameSourceOptions source_options = flags.source.Resolve();
  MapBuilderOptions options = flags.key_images.Resolve(flags.matcher.type);
  options.verifier = flags.verifier.Resolve();
  options.show_progress = spdlog::should_log(spdlog::level::info);
  options.Check();
  flags.matcher.Check();
  if (flags.write_maps && flags.output.empty()) throw InputError("--maps needs -o DIR to write the maps into");

  // The outputs are claimed before any work: each is refused here when it is not vmap's or holds the input.
  // --report DIR is the -o folder, or a sweep folder of its own (its sweep files and the page).
  std::unique_ptr<AtomicOutputDirectory> directory, report_directory;
  if (!flags.output.empty()) {
    directory = std::make_unique<AtomicOutputDirectory>(flags.output, SweepOutputPolicy(flags.input));
  }
  const bool report_in_output = directory && !flags.report.empty() && SamePath(flags.report, flags.output);
  if (!flags.report.empty() && !report_in_output) {
    if (directory && (IsSameOrInside(flags.report, flags.output) || IsSameOrInside(flags.output, flags.report))) {
      throw InputError("--report " + flags.report + " must be the -o folder or lie outside it");
    }
    report_directory = std::make_unique<AtomicOutputDirectory>(flags.report, SweepOutputPolicy(flags.input));
  }

  const std::unique_ptr<Matcher> matcher = CreateMatcher(flags.matcher);
  const std::unique_ptr<FrameSource> source = OpenFrameSource(flags.input, source_options);
  // A sweep compares every frame once for all taus, whatever the matcher: recorded as such.
  if (options.key_search == KeySearch::kAuto) options.key_search = KeySearch::kSequential;
  const std::string options_json = DescribeOptions(*matcher, options, source_options);

  // The ground truth is read before the sweep: a missing file fails at once, not after the whole input.
  std::optional<GroundTruth> truth;
  if (flags.evaluate) {
    VisualMap input_only;
    input_only.input.path = flags.input;
    input_only.input.format = source_options.format;
    truth = MapGroundTruth(input_only, flags.gt, ParseGroundTruthFormat(flags.gt_format));
  }
  std::vector<VisualMap> maps;
  const bool keep_maps = flags.write_maps || flags.evaluate;
  SweepResult sweep = SweepThresholds(*source, *matcher, options, taus, keep_maps ? &maps : nullptr,
                                      flags.write_maps ? directory->path() : fs::path(), options_json);
  std::vector<MapEvaluation> evaluations;
  if (truth && !maps.empty()) {
    // Every tau's map against the same ground truth, with the default usability criterion of `vmap eval`.
    const Camera camera = EvaluationCamera(maps.front(), "");
    for (size_t i = 0; i < maps.size(); ++i) {
      evaluations.push_back(EvaluateMap(maps[i], *truth, camera, EvaluationOptions()));
      sweep.rows[i].usable_links = evaluations.back().summary.usable_links;
    }
  }
  if (directory) {
    for (size_t i = 0; flags.write_maps && i < maps.size(); ++i) {
      // map.json, correspondences.bin and the key images are written by the sweep (MapWriter).
      if (i < evaluations.size()) {
        evaluations[i].map_path = sweep.rows[i].map_directory;
        WriteFileAtomically(fs::path(sweep.rows[i].map_directory) / kEvaluationFileName,
                            EvaluationToJson(evaluations[i]));
      }
      if (!flags.report.empty()) {
        // Each tau's map gets its own page, so the sweep page links to pages rather than to map.json.
        MapReportOptions report_options;
        report_options.route_video = false;
        WriteMapReport(sweep.rows[i].map_directory, report_options);
      }
      // Recorded relative to the sweep directory, which is renamed into place below.
      sweep.rows[i].map_directory = fs::path(sweep.rows[i].map_directory).filename().string();
    }
    WriteSweepFiles(sweep, directory->path());
    if (report_in_output) WriteSweepReport(sweep, directory->path());
    directory->Commit();
  }
  if (report_directory) {
    // The per-tau maps are linked from the page: give their final paths.
    SweepResult linked = sweep;
    for (SweepRow& row : linked.rows) {
      if (row.map_directory.empty()) continue;
      row.map_directory = fs::absolute(fs::path(flags.output) / row.map_directory).string();
    }
    WriteSweepFiles(linked, report_directory->path());
    WriteSweepReport(linked, report_directory->path());
    report_directory->Commit();
  }
  std::cout << SweepToMarkdown(sweep);
  if (directory) std::cout << "\nwritten to " << flags.output << " (sweep.md, sweep.csv, sweep.json)\n";
}

}  // namespace

void AddSweepCommand(CLI::App& app) {
  auto flags = std::make_shared<SweepFlags>();
  CLI::App* command =
      app.add_subcommand("sweep", "Build maps for a range of thresholds tau in one pass (the paper's tables)");
  command->add_option("input", flags->input, "Video file, image folder, TUM RGB-D, EuRoC or KITTI sequence")
      ->required();
  flags->option_flags
      .AddOption(command, "--thresholds", flags->thresholds, "thresholds", "start:stop:step or a list a,b,c")
      ->capture_default_str();
  command->add_option("-o,--output", flags->output, "Directory for sweep.md, sweep.csv and sweep.json");
  command->add_flag("--maps", flags->write_maps, "Also write each tau's map into the output directory");
  command->add_option("--report", flags->report, "Write an HTML report of the sweep into this directory");
  AddSourceOptions(command, flags->source, flags->option_flags);
  AddMatcherOptions(command, flags->matcher, flags->option_flags);
  AddVerifierOptions(command, flags->verifier, flags->option_flags);
  AddKeyImageOptions(command, flags->key_images, flags->option_flags, /*with_tau=*/false);
  CLI::Option* gt = flags->option_flags
                        .AddOption(command, "--gt", flags->gt, "gt.path",
                                   "Add a usable-links column (see `vmap eval`): with no FILE, the input's own "
                                   "ground truth; or a kitti, tum or euroc poses file")
                        ->expected(0, 1);
  flags->option_flags
      .AddOption(command, "--gt-format", flags->gt_format, "gt.format",
                 "Format of --gt FILE: " + ListEnumNames(kGroundTruthFormatNames))
      ->capture_default_str();
  command->callback([flags, gt] {
    flags->evaluate = gt->count() > 0;
    flags->option_flags.Run([&] { RunSweep(*flags); });
  });
}

}  // namespace vmap::cli
