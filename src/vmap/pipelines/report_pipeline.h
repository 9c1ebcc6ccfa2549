#pragma once
// The report pipeline: the offline HTML report of a map (report.html inside it) or of a localization run (the
// JSON of `vmap localize --json`), as `vmap report TARGET` writes them.

#include <filesystem>
#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/report/html_report.h"

namespace vmap {

struct ReportPipelineOptions {
  std::string target;  // a map directory, or a localization run's JSON file
  std::string output;  // a run's report folder; "" = "<run file name>_report" beside the run file
  MapReportOptions map_report;

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Stages, in order:
//   1. check the options;
//   2. tell a map from a run (anything but a folder is taken for a run, whose reader refuses what is not a
//      regular file; a .json that does not exist is a run that does not exist, anything else a map); the options of
//      the other kind of report are refused (OptionError), not ignored;
//   3. write the report: into the map, or into the run's report folder.
// Returns the report's page.
std::filesystem::path RunReportPipeline(const ReportPipelineOptions& options);

}  // namespace vmap
