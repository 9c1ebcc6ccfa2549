// vmap report MAP_DIR: writes report.html (summary, key-image strip, match figures, plots) into a map.

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_flags.h"
#include "vmap/report/html_report.h"
#include "vmap/report/localization_report.h"

namespace vmap::cli {

namespace {

// `target`: a map directory, or the --json file of `vmap localize` (then `run_output` is where its report goes).
void RunReport(const std::filesystem::path& target, const std::string& run_output, const MapReportOptions& options) {
  // Anything but a folder is taken for a run's file, whose reader refuses what is not a regular file.
  std::error_code ec;
  if (std::filesystem::exists(target, ec) && !std::filesystem::is_directory(target, ec)) {
    const std::filesystem::path output = run_output.empty()
                                             ? target.parent_path() / (target.stem().string() + "_report")
                                             : std::filesystem::path(run_output);
    WriteLocalizationReport(target, output);
    std::cout << "report          " << (output / kReportFileName).string() << "\n";
    return;
  }
  WriteMapReport(target, options);
  std::cout << "report          " << (target / kReportFileName).string() << "\n";
}

}  // namespace

void AddReportCommand(CLI::App& app) {
  auto map_directory = std::make_shared<std::string>();
  auto options = std::make_shared<MapReportOptions>();
  auto run_output = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "report",
      "Write report.html into a map directory: summary, key images, match figures and plots (offline "
      "page); or, given the --json file of `vmap localize`, the report of that localization run");
  command->add_option("map", *map_directory, "Map directory written by `vmap build`, or a `vmap localize --json` file")
      ->required();
  command->add_option("-o,--output", *run_output,
                      "Localization runs: directory for report.html (default: <run file name>_report beside it)");
  auto option_flags = std::make_shared<OptionFlags>();
  option_flags
      ->AddOption(command, "--thumbnail-width", options->thumbnail_width, "thumbnail_width",
                  "Width of the key-image thumbnails in pixels")
      ->capture_default_str()
      ->check(CLI::Range(32, 4096));
  option_flags
      ->AddOption(command, "--figure-width", options->figure_width, "figure_width",
                  "Width of the match figures in pixels")
      ->capture_default_str()
      ->check(CLI::Range(64, 8192));
  option_flags->AddFlag(command, "!--no-video", options->route_video, "route_video",
                        "Skip report/route.mp4, the video of the key images in order");
  command->callback([map_directory, options, run_output, option_flags] {
    option_flags->Run([&] { RunReport(*map_directory, *run_output, *options); });
  });
}

}  // namespace vmap::cli
