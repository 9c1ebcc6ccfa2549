// vmap build INPUT -o MAP_DIR: the paper's pipeline end to end.

#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/common_options.h"
#include "vmap/cli/map_options.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/core/interrupt.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/map_builder.h"
#include "vmap/map/map_io.h"
#include "vmap/map/map_writer.h"
#include "vmap/report/summary.h"
#include "vmap/sources/read_ahead_source.h"

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
  double snapshot_every = 0.0;  // seconds; 0 = no snapshots
  bool until_interrupted = false;
  OptionFlags option_flags;
};

// Streams the input through a MapBuilder: snapshots while it runs, the end of the input on SIGINT when asked.
VisualMap BuildStreaming(const BuildFlags& flags, FrameSource& input, const Matcher& matcher,
                         const MapBuilderOptions& options, const AtomicOutputDirectory& directory,
                         const std::string& options_json) {
  std::optional<SnapshotTarget> snapshots;
  if (flags.snapshot_every > 0) snapshots = SnapshotTarget{directory.final_path(), MapOutputPolicy(flags.input)};
  MapWriter writer(directory.path(), snapshots);
  // Decoded on a thread of its own, while this one runs Algorithm 1 (see BuildMap).
  ReadAheadSource source(input, options.prefetch_frames);
  MapBuilder builder(source, matcher, options, &writer, options_json);
  using Clock = std::chrono::steady_clock;
  auto last_snapshot = Clock::now();
  bool interrupted = false;
  for (;;) {
    if (flags.until_interrupted && InputEndRequested()) {
      interrupted = true;
      break;
    }
    std::optional<Frame> frame = source.Next();
    if (!frame) {
      interrupted = flags.until_interrupted && InputEndRequested();
      break;
    }
    builder.Add(std::move(*frame));
    // Between frames: a source that waits long for its next frame delays the snapshot as long.
    if (snapshots && std::chrono::duration<double>(Clock::now() - last_snapshot).count() >= flags.snapshot_every) {
      builder.Snapshot();
      last_snapshot = Clock::now();
      spdlog::debug("snapshot written to {}", directory.final_path().string());
    }
  }
  if (interrupted) spdlog::info("input ended by SIGINT: finishing the map from the frames seen");
  return builder.Finish(interrupted ? CoverageEnd::kInterrupted : CoverageEnd::kInputEnded);
}

void RunBuild(const BuildFlags& flags) {
  FrameSourceOptions source_options = flags.source.Resolve();
  MapBuilderOptions options = flags.key_images.Resolve(flags.matcher.type);
  options.verifier = flags.verifier.Resolve();
  options.show_progress = spdlog::should_log(spdlog::level::info);
  options.Check();
  flags.matcher.Check();
  if (!(flags.snapshot_every >= 0.0 && flags.snapshot_every <= 86400.0)) {
    throw InputError("--snapshot-every must be 0 (no snapshots) to 86400 seconds");
  }
  const bool streaming = flags.snapshot_every > 0 || flags.until_interrupted;
  if (streaming && ResolveKeySearch(options) == KeySearch::kBisect) {
    throw InputError("--snapshot-every and --until-interrupted build the map frame by frame, and --search bisect "
                     "reads ahead; drop --search bisect");
  }
  const fs::path output = flags.output.empty() ? fs::path(fs::path(flags.input).filename().stem().string() + "_map")
                                               : fs::path(flags.output);
  // Before any work: an output that is not vmap's, or that holds the input, is refused here.
  AtomicOutputDirectory directory(output, MapOutputPolicy(flags.input));
  const std::unique_ptr<Matcher> matcher = CreateMatcher(flags.matcher);
  if (flags.until_interrupted) {
    EndInputOnSigint(true);
    source_options.stop_requested = [] { return InputEndRequested(); };
  }
  const std::unique_ptr<FrameSource> source = OpenFrameSource(flags.input, source_options);
  const std::string options_json = DescribeOptions(*matcher, options, source_options);
  const VisualMap map = ResolveKeySearch(options) == KeySearch::kBisect
                            ? BuildMap(*source, *matcher, options, directory.path(), options_json)
                            : BuildStreaming(flags, *source, *matcher, options, directory, options_json);
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
  AddSourceOptions(command, flags->source, flags->option_flags);
  AddMatcherOptions(command, flags->matcher, flags->option_flags);
  AddVerifierOptions(command, flags->verifier, flags->option_flags);
  AddKeyImageOptions(command, flags->key_images, flags->option_flags);
  command->add_flag("--report", flags->report, "Also write report.html into the map directory");
  command->add_option("--snapshot-every", flags->snapshot_every,
                      "Seconds between snapshots: the map so far, written to the output directory while the run "
                      "goes on (0 = none)");
  command->add_flag("--until-interrupted", flags->until_interrupted,
                    "SIGINT (Ctrl-C) ends the input and the map is finished from the frames seen (a second SIGINT "
                    "aborts); for cameras and streams");
  command->callback([flags] { flags->option_flags.Run([&] { RunBuild(*flags); }); });
}

}  // namespace vmap::cli
