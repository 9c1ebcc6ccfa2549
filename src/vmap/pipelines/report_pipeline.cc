#include "vmap/pipelines/report_pipeline.h"

#include <optional>

#include "vmap/core/directory_lock.h"
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

fs::path RunReportPipeline(const ReportPipelineOptions& options) {
  // 1. The options.
  options.Check();

  // 2. A map or a run.
  const fs::path target(options.target);
  std::error_code ec;
  const bool is_run = fs::exists(target, ec) && !fs::is_directory(target, ec);

  // 3. The report.
  if (is_run) {
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
