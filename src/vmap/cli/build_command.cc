// vmap build INPUT -o MAP_DIR: the paper's pipeline end to end.

#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/common_options.h"
#include "vmap/cli/map_options.h"
#include "vmap/core/atomic_output.h"
#include "vmap/mapping/map_builder.h"
#include "vmap/map/map_io.h"
#include "vmap/report/summary.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct BuildFlags {
  std::string input;
  std::string output;
  SourceFlags source;
  MatcherOptions matcher;
  VerifierFlags verifier;
  KeyImageFlags key_images;
  bool report = false;
};

void RunBuild(const BuildFlags& flags) {
  const FrameSourceOptions source_options = flags.source.Resolve();
  MapBuilderOptions options = flags.key_images.Resolve(flags.matcher.type);
  options.verifier = flags.verifier.Resolve();
  options.show_progress = spdlog::should_log(spdlog::level::info);
  options.Check();
  flags.matcher.Check();
  const fs::path output = flags.output.empty() ? fs::path(fs::path(flags.input).filename().stem().string() + "_map")
                                               : fs::path(flags.output);
  // Before any work: an output that is not vmap's, or that holds the input, is refused here.
  AtomicOutputDirectory directory(output, MapOutputPolicy(flags.input));
  const std::unique_ptr<Matcher> matcher = CreateMatcher(flags.matcher);
  const std::unique_ptr<FrameSource> source = OpenFrameSource(flags.input, source_options);
  const std::string options_json = DescribeOptions(*matcher, options, source_options);
  const VisualMap map = BuildMap(*source, *matcher, options, directory.path(), options_json);
  WriteMapFiles(map, directory.path());
  WriteReportIfAsked(flags.report, directory.path());
  directory.Commit();
  std::cout << FormatMapSummary(map, options.quality_mean) << "map             " << output.string() << "\n";
}

}  // namespace

void AddBuildCommand(CLI::App& app) {
  auto flags = std::make_shared<BuildFlags>();
  CLI::App* command = app.add_subcommand("build", "Build a visual map from a video, image folder or dataset");
  command->add_option("input", flags->input, "Video file, image folder, TUM RGB-D, EuRoC or KITTI sequence")
      ->required();
  command->add_option("-o,--output", flags->output, "Map directory to write (default: <input name>_map)");
  AddSourceOptions(command, flags->source);
  AddMatcherOptions(command, flags->matcher);
  AddVerifierOptions(command, flags->verifier);
  AddKeyImageOptions(command, flags->key_images);
  command->add_flag("--report", flags->report, "Also write report.html into the map directory");
  command->callback([flags] { RunBuild(*flags); });
}

}  // namespace vmap::cli
