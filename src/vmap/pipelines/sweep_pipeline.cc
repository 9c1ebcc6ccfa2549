#include "vmap/pipelines/sweep_pipeline.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/mapping/sweep_thresholds.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/report/html_report.h"
#include "vmap/report/summary.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// Whether two output paths name the same folder (neither need exist yet).
bool SamePath(const std::string& a, const std::string& b) {
  std::error_code ec;
  return fs::weakly_canonical(fs::absolute(a), ec) == fs::weakly_canonical(fs::absolute(b), ec);
}

void WriteSweepFiles(const SweepResult& sweep, const fs::path& directory) {
  WriteFileAtomically(directory / "sweep.md", SweepToMarkdown(sweep));
  WriteFileAtomically(directory / "sweep.csv", SweepToCsv(sweep));
  WriteFileAtomically(directory / kSweepJsonFileName, SweepToJson(sweep));
}

}  // namespace

void SweepPipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"input", "input", "Video file, image folder, TUM RGB-D, EuRoC or KITTI sequence"}
                    .Positional()
                    .NotRecorded(),
                input);
  visitor.Section("Sweep: the thresholds and what is written");
  visitor.Visit(OptionField{"thresholds", "--thresholds", "start:stop:step or a list a,b,c"}.NotRecorded(), thresholds);
  visitor.Visit(OptionField{"output", "-o,--output", "Directory for sweep.md, sweep.csv and sweep.json"}
                    .HideDefault()
                    .NotRecorded(),
                output);
  visitor.Visit(
      OptionField{"write_maps", "--maps", "Also write each tau's map into the output directory"}.NotRecorded(),
      write_maps);
  visitor.Visit(OptionField{"report", "--report", "Write an HTML report of the sweep into this directory"}
                    .HideDefault()
                    .NotRecorded(),
                report);
  visitor.VisitNested("", source);
  visitor.VisitNested("", matcher);
  visitor.VisitNested("verifier", map.verifier);  // first, as `vmap sweep --help` has always listed them
  visitor.VisitNested("", map, Nesting{false, {"verifier"}});
  // --gt takes its FILE or none (the input's own ground truth): the CLI binds it to both fields.
  visitor.Visit(OptionField{"evaluate"}.NotRecorded(), evaluate);
  visitor.VisitNested("gt", gt, Nesting{false, {"path"}});
}

void SweepPipelineOptions::Check() const {
  ParseThresholds(thresholds);
  source.Check();
  ResolvedMapOptions().Check();
  matcher.Check();
  if (write_maps && output.empty()) {
    throw OptionError("write_maps", "needs output, the folder to write the maps into", {"output"});
  }
}

MapBuilderOptions SweepPipelineOptions::ResolvedMapOptions() const {
  MapBuilderOptions resolved = map;
  resolved.key_images.tau = DefaultTau(matcher.type);
  return resolved;
}

SweepResult RunSweepPipeline(const SweepPipelineOptions& options) {
  // 1. The options and the thresholds.
  options.Check();
  const std::vector<double> taus = ParseThresholds(options.thresholds);
  MapBuilderOptions map_options = options.ResolvedMapOptions();
  map_options.show_progress = map_options.show_progress && spdlog::should_log(spdlog::level::info);

  // 2. The outputs, claimed before any work: each is refused here when it is not vmap's or holds the input.
  // The report is the output folder, or a sweep folder of its own (its sweep files and the page).
  std::unique_ptr<AtomicOutputDirectory> directory, report_directory;
  if (!options.output.empty()) {
    directory = std::make_unique<AtomicOutputDirectory>(options.output, SweepOutputPolicy(options.input));
  }
  const bool report_in_output = directory && !options.report.empty() && SamePath(options.report, options.output);
  if (!options.report.empty() && !report_in_output) {
    if (directory &&
        (IsSameOrInside(options.report, options.output) || IsSameOrInside(options.output, options.report))) {
      throw OptionError("report", "'" + options.report + "' must be the output folder or lie outside it", {"output"});
    }
    report_directory = std::make_unique<AtomicOutputDirectory>(options.report, SweepOutputPolicy(options.input));
  }

  // 3. The matcher and the input.
  const std::unique_ptr<Matcher> matcher = CreateMatcher(options.matcher);
  const std::unique_ptr<FrameSource> source = OpenFrameSource(options.input, options.source);
  // A sweep compares every frame once for all taus, whatever the matcher: recorded as such.
  if (map_options.key_search == KeySearch::kAuto) map_options.key_search = KeySearch::kSequential;
  const std::string options_json = DescribeMapOptions(*matcher, map_options, options.source);

  // 4. The ground truth.
  std::optional<GroundTruth> truth;
  if (options.evaluate) {
    VisualMap input_only;
    input_only.input.path = options.input;
    input_only.input.format = source->info().format;  // as detected: KITTI poses go by file number in a KITTI sequence
    truth = MapGroundTruth(input_only, options.gt.path, options.gt.format);
  }

  // 5. Every τ, in one pass.
  std::vector<VisualMap> maps;
  const bool keep_maps = options.write_maps || options.evaluate;
  SweepResult sweep = SweepThresholds(*source, *matcher, map_options, taus, keep_maps ? &maps : nullptr,
                                      options.write_maps ? directory->path() : fs::path(), options_json);
  // The sweep's record names the τ it tried, not the one its options were described with (the matcher's default,
  // which each map written replaces with its own).
  nlohmann::json recorded = nlohmann::json::parse(options_json);
  recorded.erase("tau");
  recorded["thresholds"] = taus;
  sweep.options_json = recorded.dump();

  // 6. Every τ's map against the same ground truth, with the default usability criterion of `vmap eval`.
  std::vector<MapEvaluation> evaluations;
  if (truth && !maps.empty()) {
    const Camera camera = EvaluationCamera(maps.front(), "");
    for (size_t i = 0; i < maps.size(); ++i) {
      evaluations.push_back(EvaluateMap(maps[i], *truth, camera, EvaluationOptions()));
      sweep.rows[i].usable_links = evaluations.back().summary.usable_links;
    }
  }

  // 7. The files.
  if (directory) {
    for (size_t i = 0; options.write_maps && i < maps.size(); ++i) {
      // map.json, correspondences.bin and the key images are written by the sweep (MapWriter).
      if (i < evaluations.size()) {
        evaluations[i].map_path = sweep.rows[i].map_directory;
        WriteFileAtomically(fs::path(sweep.rows[i].map_directory) / kEvaluationFileName,
                            EvaluationToJson(evaluations[i]));
      }
      if (!options.report.empty()) {
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
      row.map_directory = fs::absolute(fs::path(options.output) / row.map_directory).string();
    }
    WriteSweepFiles(linked, report_directory->path());
    WriteSweepReport(linked, report_directory->path());
    report_directory->Commit();
  }
  return sweep;
}

}  // namespace vmap
