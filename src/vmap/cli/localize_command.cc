// vmap localize MAP QUERY: the localization pipeline (pipelines/localize_pipeline.h) over every frame of a repeat
// run (or one image), and its summary.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/pipelines/localize_pipeline.h"
#include "vmap/report/html_report.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct LocalizeCommand {
  LocalizePipelineOptions options;
  OptionFlags flags;
};

std::string Percent(long part, long whole) { return whole > 0 ? fmt::format("{:.1f}%", 100.0 * part / whole) : "-"; }

void RunLocalize(const LocalizeCommand& command) {
  const LocalizePipelineOptions& options = command.options;
  options.session.CheckGiven(command.flags.Given());
  const LocalizePipelineResult result = RunLocalizePipeline(options);
  const LocalizationRun& run = result.run;
  const LocalizationSummary& s = run.summary;
  std::cout << fmt::format("map             {} ({} key images, {})\n", options.map, result.map.key_images.size(),
                           run.info.matcher)
            << fmt::format("query           {} ({})\n", options.query, SourceFormatName(run.info.query_format))
            << fmt::format("key images      {:.2f} s (cache: {}), ranking by {}\n", run.info.key_image_seconds,
                           run.info.cache, run.info.ranking)
            << fmt::format("frames          {}\n", s.frames)
            << fmt::format("tracking        {} ({})\n", s.tracking, Percent(s.tracking, s.frames))
            << fmt::format("relocalized     {} ({})\n", s.relocalized, Percent(s.relocalized, s.frames))
            << fmt::format("lost            {} ({})\n", s.lost, Percent(s.lost, s.frames))
            << fmt::format("uncertain       {} ({})\n", s.uncertain, Percent(s.uncertain, s.frames))
            << fmt::format("time            {:.2f} s ({:.1f} frames/s)\n", s.seconds, s.frames_per_second);
  if (result.with_camera) {
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
  if (!options.csv.empty()) std::cout << "csv             " << options.csv << "\n";
  if (!options.json.empty()) std::cout << "json            " << options.json << "\n";
  if (!options.report.empty()) {
    std::cout << "report          " << (fs::path(options.report) / kReportFileName).string() << "\n";
  }
}

}  // namespace

void AddLocalizeCommand(CLI::App& app) {
  auto state = std::make_shared<LocalizeCommand>();
  CLI::App* command = app.add_subcommand(
      "localize", "Localize a repeat run (video, image folder, dataset or one image) against a map, frame by frame");
  AddOptionFlags(command, state->options, state->flags);
  command->callback([state] { state->flags.Run([&] { RunLocalize(*state); }); });
}

}  // namespace vmap::cli
