#include "vmap/pipelines/report_pipeline.h"

#include <optional>

#include "vmap/core/directory_lock.h"
#include "vmap/core/error.h"
#include "vmap/report/localization_report.h"

namespace vmap {
namespace fs = std::filesystem;

void ReportPipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"target", "map", "Map directory written by `vmap build`, or a `vmap localize --json` file"}
                    .Positional(),
                target);
  visitor.Visit(OptionField{"output", "-o,--output",
                            "Localization runs: directory for report.html (default: <run file name>_report beside it)"}
                    .HideDefault()
                    .NotRecorded(),
                output);
  visitor.VisitNested("", map_report);
}

void ReportPipelineOptions::Check() const { map_report.Check(); }

namespace {

// The options of one kind of report given for the other are refused, not ignored: `vmap report MAP -o elsewhere`
// wrote into the map, and a run's report took --figure-width without using it.
void RefuseOptionsOfTheOtherReport(const ReportPipelineOptions& options, bool is_run) {
  if (!is_run) {
    if (!options.output.empty()) {
      const std::string page = (fs::path(options.target) / kReportFileName).string();
      throw OptionError("output", "is for the report of a localization run; a map's report is written into the map ('" +
                                      page + "'): leave it out, or give the run's --json file");
    }
    return;
  }
  const MapReportOptions map_defaults;
  const auto refuse = [&](const char* field, const char* what) {
    throw OptionError(field, std::string("is for a map's report, and '") + options.target +
                                 "' is a localization run, whose report has no " + what + ": leave it out");
  };
  if (options.map_report.thumbnail_width != map_defaults.thumbnail_width) refuse("thumbnail_width", "thumbnails");
  if (options.map_report.figure_width != map_defaults.figure_width) refuse("figure_width", "match figures");
  if (options.map_report.route_video != map_defaults.route_video) refuse("route_video", "route video");
}

}  // namespace

fs::path RunReportPipeline(const ReportPipelineOptions& options) {
  // 1. The options.
  options.Check();

  // 2. A map or a run.
  const fs::path target(options.target);
  std::error_code ec;
  const bool exists = fs::exists(target, ec);
  // Named as what it was meant to be: the map's report checked its page's folder first, and advised creating it.
  const fs::path named = target.has_filename() ? target : target.parent_path();  // "run.json/" names run.json
  if (!exists && named != target && fs::is_regular_file(named, ec)) {
    throw InputError("'" + target.string() + "' names the file '" + named.string() + "' as a folder; give '" +
                     named.string() + "'");
  }
  if (!exists && named.extension() == ".json") {
    throw InputError("the localization run '" + target.string() +
                     "' does not exist; give the --json file of `vmap localize`");
  }
  const bool is_run = exists && !fs::is_directory(target, ec);
  RefuseOptionsOfTheOtherReport(options, is_run);

  // 3. The report.
  if (is_run) {
    // The run a report keeps of itself: its default report would go inside that report, which could then never be
    // replaced (it holds a folder no localization report holds).
    const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    if (options.output.empty() && target.filename() == kLocalizationReportRunFileName &&
        fs::is_regular_file(parent / kReportFileName, ec)) {
      throw InputError("'" + target.string() + "' is the run kept in the report '" + parent.string() +
                       "': its report would go inside that one; give -o with a folder outside it");
    }
    const fs::path output =
        options.output.empty() ? target.parent_path() / (target.stem().string() + "_report") : fs::path(options.output);
    WriteLocalizationReport(target, output);
    return output / kReportFileName;
  }
  // A writer of the map's folder: a rebuild replacing the map meanwhile waits, and so does the report for one under
  // way, so that the page put in the map describes that map. (Not in WriteMapReport: a build writes its report into
  // its own temporary, which it holds locked itself.)
  std::optional<DirectoryWriteLock> writing;
  if (fs::is_directory(target, ec)) writing.emplace(target, "the map");
  WriteMapReport(target, options.map_report);
  return target / kReportFileName;
}

}  // namespace vmap
