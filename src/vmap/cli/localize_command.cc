// vmap localize MAP QUERY: localizes every frame of a repeat run (or one image) against a map.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/common_options.h"
#include "vmap/cli/localize_odometry.h"
#include "vmap/cli/localize_options.h"
#include "vmap/cli/output_files.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localization_output.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/route.h"
#include "vmap/map/map_io.h"
#include "vmap/report/localization_report.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct LocalizeFlags : LocalizerFlags {
  std::string map;
  std::string query;
  std::string csv;
  std::string json;
  std::string report;
  SourceFlags source;
  OdometryFlags odometry;
  OptionFlags option_flags;
};

std::string Percent(long part, long whole) { return whole > 0 ? fmt::format("{:.1f}%", 100.0 * part / whole) : "-"; }

void RunLocalize(const LocalizeFlags& flags) {
  LocalizationSetup setup = SetUpLocalization(flags, flags.source.Resolve(), flags.map, flags.query, [&] {
    CheckOutputs(
        {{flags.csv, "--csv"}, {flags.json, "--json"}},
        {MapInputs(flags.map), NamedInput(flags.query, "the query"), NamedInput(flags.report, "the --report folder")});
    if (!flags.report.empty()) CheckLocalizationReportDirectory(flags.report, flags.map, flags.query);
    // A FIFO or a device other than a camera would be opened blocking, waiting for a writer that may never come.
    std::error_code ec;
    const fs::file_status query_status = fs::status(flags.query, ec);
    if (!IsLiveInput(flags.query) && fs::exists(query_status) && !fs::is_regular_file(query_status) &&
        !fs::is_directory(query_status)) {
      throw InputError("query '" + flags.query +
                       "' is neither a file nor a folder (a FIFO or a device); give a "
                       "video, an image folder, a TUM/EuRoC/KITTI sequence, an image, or a live input (udp://..., "
                       "/dev/videoN)");
    }
  });
  const FrameSourceOptions& source_options = setup.source_options;
  const LocalizeSequenceOptions& run_options = setup.run_options;
  const std::unique_ptr<FrameSource>& source = setup.source;
  const LocalizationMap& opened = *setup.opened;
  const LocalizerOptions& options = setup.options;
  const VisualMap& map = opened.map;
  Localizer localizer(map, opened.keys, *opened.matcher, options);

  LocalizationRun run;
  run.info.map_directory = flags.map;
  run.info.query = flags.query;
  run.info.query_format = source->info().format;
  run.info.source = source_options;
  run.info.matcher = opened.matcher->name();
  run.info.ranking = RankingMethodName(localizer.ranking_method());
  run.info.cache = KeyImageCacheStateName(opened.keys.cache);
  run.info.key_image_seconds = opened.keys.seconds;
  run.info.options_json = DescribeLocalizerOptions(options);
  run.info.experiences = !opened.experiences.empty();
  std::string csv = LocalizationCsvHeader(run.info.experiences);
  // With odometry, its columns come last on every row (csv and json).
  std::optional<OdometryProgress> odometry = OpenQueryOdometry(flags.odometry, flags.query);
  nlohmann::json odometry_json = nlohmann::json::array();
  if (odometry) csv.insert(csv.size() - 1, OdometryCsvColumns());
  // A query that cannot be read again (a live input, a single image) leaves its report the frames kept here:
  // the last ones, as many as the report shows.
  const LocalizationReportOptions report_options;
  const bool record = !flags.report.empty() && !QueryCanBeReadAgain(run.info);
  RecordedFrames recorded;
  run.summary = LocalizeSequence(*source, *opened.matcher, localizer, run_options,
                                 [&](const Frame& frame, const LocalizationResult& result) {
                                   std::string row = LocalizationCsvRow(map, result, run.info.experiences);
                                   if (odometry) {
                                     const FrameOdometry at = odometry->Update(result);
                                     row.insert(row.size() - 1, OdometryCsvCells(at));
                                     odometry_json.push_back(OdometryJson(result.frame_index, at));
                                   }
                                   if (!flags.csv.empty()) csv += row;
                                   run.frames.push_back(result);
                                   if (record && report_options.pairs > 0) {
                                     recorded[result.frame_index] = ColorImage(frame);
                                     if (recorded.size() > static_cast<size_t>(report_options.pairs)) {
                                       recorded.erase(recorded.begin());
                                     }
                                   }
                                 });
  run.info.frame_size = source->info().frame_size;

  if (!flags.csv.empty()) WriteFileAtomically(flags.csv, csv);
  if (!flags.json.empty()) {
    std::string json = LocalizationRunJson(map, run);
    if (odometry) {
      nlohmann::json document = nlohmann::json::parse(json);
      document["odometry"] = std::move(odometry_json);
      json = document.dump(1) + "\n";
    }
    WriteFileAtomically(flags.json, json);
  }
  if (!flags.report.empty()) WriteLocalizationReport(run, map, flags.map, flags.report, report_options, recorded);

  const LocalizationSummary& s = run.summary;
  std::cout << fmt::format("map             {} ({} key images, {})\n", flags.map, map.key_images.size(),
                           opened.matcher->name())
            << fmt::format("query           {} ({})\n", flags.query, SourceFormatName(run.info.query_format))
            << fmt::format("key images      {:.2f} s (cache: {}), ranking by {}\n", opened.keys.seconds, run.info.cache,
                           run.info.ranking)
            << fmt::format("frames          {}\n", s.frames)
            << fmt::format("tracking        {} ({})\n", s.tracking, Percent(s.tracking, s.frames))
            << fmt::format("relocalized     {} ({})\n", s.relocalized, Percent(s.relocalized, s.frames))
            << fmt::format("lost            {} ({})\n", s.lost, Percent(s.lost, s.frames))
            << fmt::format("uncertain       {} ({})\n", s.uncertain, Percent(s.uncertain, s.frames))
            << fmt::format("time            {:.2f} s ({:.1f} frames/s)\n", s.seconds, s.frames_per_second);
  if (options.camera) {
    const auto heading_only = std::count_if(run.frames.begin(), run.frames.end(), [](const LocalizationResult& r) {
      return LocalizationGuidance(r) == "heading only: translation unknown";
    });
    std::cout << fmt::format("heading only    {} frames: translation to the target unknown ({})\n", heading_only,
                             Percent(heading_only, s.frames));
  }
  if (run.frames.size() == 1) {
    const LocalizationResult& r = run.frames.front();
    std::cout << fmt::format("status          {}\n", LocalizationStatusName(r.status))
              << fmt::format("key             {} -> next {}\n", r.key, r.next_key)
              << fmt::format("guidance        {}\n", LocalizationGuidance(r));
  }
  if (!flags.csv.empty()) std::cout << "csv             " << flags.csv << "\n";
  if (!flags.json.empty()) std::cout << "json            " << flags.json << "\n";
  if (!flags.report.empty())
    std::cout << "report          " << (fs::path(flags.report) / "report.html").string() << "\n";
}

}  // namespace

void AddLocalizeCommand(CLI::App& app) {
  auto flags = std::make_shared<LocalizeFlags>();
  CLI::App* command = app.add_subcommand(
      "localize", "Localize a repeat run (video, image folder, dataset or one image) against a map, frame by frame");
  command->add_option("map", flags->map, "Map directory written by `vmap build`")->required();
  command->add_option("query", flags->query, "Video, image folder, TUM/EuRoC/KITTI sequence, or a single image")
      ->required();
  command->add_option("--csv", flags->csv, "Write one row per frame to this CSV file");
  command->add_option("--json", flags->json, "Write the run (summary and every frame) to this JSON file");
  command->add_option("--report", flags->report, "Write an HTML report of the run into this directory");
  OptionFlags& option_flags = flags->option_flags;
  AddSourceOptions(command, flags->source, option_flags);
  AddLocalizerOptions(command, *flags, option_flags);
  AddOdometryOptions(command, flags->odometry, option_flags);
  command->callback([flags] { flags->option_flags.Run([&] { RunLocalize(*flags); }); });
}

}  // namespace vmap::cli
