#pragma once
// The HTML report of a localization run (`vmap localize --report DIR`, or `vmap report RUN.json`): one page
// that opens offline, in the style of the map report.
//
//   DIR/report.html               the page: summary, key image over time (with the status of every frame),
//                                 S against the key image and the next one, and a few frames beside the key
//                                 image they were localized at
//   DIR/report/frames/NNNNNN.jpg  those pairs (NNNNNN = frame index)
//   DIR/run.json                  the run (as `vmap localize --json` writes it)
// DIR is written as a whole and replaced atomically, and only when it is empty or an older report of a run
// (its run.json says so, and it holds nothing a report does not write, inside report/ neither), never a folder
// that is, holds or lies inside the map or the query.

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/option_fields.h"
#include "vmap/localization/localization_output.h"
#include "vmap/map/visual_map.h"

namespace vmap {

inline constexpr const char* kLocalizationReportRunFileName = "run.json";

struct LocalizationReportOptions {
  int pairs = 8;         // frames shown beside their key image (spread over the run, lost ones first)
  int pair_width = 960;  // width of each pair in pixels
  int jpeg_quality = 85;

  // No flags: the run's report is made as it is.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Query frames (colour) kept by the run itself, by frame index: the pictures of a report whose query cannot
// be read again.
using RecordedFrames = std::map<int, cv::Mat>;

// Whether the run's query can be read again for the report's pictures: not a live input (a stream, a camera),
// not a single image (its frame is kept by the run instead), nor a FIFO or device.
bool QueryCanBeReadAgain(const LocalizationRunInfo& info);

// `map` is the map the run localized against, read from `map_directory`. The query frames shown are
// `recorded` when it is not empty, else read again from the run's query where it can be
// (QueryCanBeReadAgain); otherwise the page says why it shows none. Throws InputError when a file cannot be
// read or written.
void WriteLocalizationReport(const LocalizationRun& run, const VisualMap& map,
                             const std::filesystem::path& map_directory, const std::filesystem::path& directory,
                             const LocalizationReportOptions& options = {}, const RecordedFrames& recorded = {});
// WriteLocalizationReport's work but its last step: the report written into its temporary folder, which Commit()
// puts in place. `vmap localize` writes all its outputs before it puts any in place (PendingFile).
std::unique_ptr<AtomicOutputDirectory> PrepareLocalizationReport(const LocalizationRun& run, const VisualMap& map,
                                                                 const std::filesystem::path& map_directory,
                                                                 const std::filesystem::path& directory,
                                                                 const LocalizationReportOptions& options = {},
                                                                 const RecordedFrames& recorded = {});

// Throws InputError when `directory` may not receive the report of a run against `map_directory` of `query`
// (the check WriteLocalizationReport makes): for `vmap localize --report`, to refuse before the run.
void CheckLocalizationReportDirectory(const std::filesystem::path& directory,
                                      const std::filesystem::path& map_directory, const std::string& query);

// "" when `directory` is a localization report vmap wrote (its run.json is a run), or why it is not.
std::string WhyNotALocalizationReport(const std::filesystem::path& directory);

// Reads the run (ReadLocalizationRun) and its map, and writes the report into `directory`. The map directory
// and the query recorded in the run are taken as they are, or relative to the run file's folder when they
// are not found as they are.
void WriteLocalizationReport(const std::filesystem::path& run_file, const std::filesystem::path& directory,
                             const LocalizationReportOptions& options = {});

}  // namespace vmap
