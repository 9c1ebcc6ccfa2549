// vmap build INPUT -o MAP_DIR: the paper's pipeline end to end.

#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/common_options.h"
#include "vmap/cli/map_options.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/core/interrupt.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/localization/add_experience.h"
#include "vmap/map/map_io.h"
#include "vmap/map/map_writer.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/map_builder.h"
#include "vmap/mapping/recorded_options.h"
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
  std::string add_experience_to;  // a map: the input is added to it as an experience instead of building one
  AddExperienceOptions experience;
  bool matcher_given = false;
  bool acceptance_given = false;  // one of --acceptance, --max-log10-nfa, --min-verified, --min-similarity
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

// vmap build REPEAT --add-experience-to MAP: the input is localized against MAP and added as an experience.
void RunAddExperience(const BuildFlags& flags) {
  if (!flags.output.empty()) {
    throw InputError("--add-experience-to adds to the map it names; drop -o " + flags.output);
  }
  if (flags.snapshot_every > 0 || flags.until_interrupted || flags.report) {
    throw InputError(
        "--add-experience-to takes a whole recorded run; drop --snapshot-every, --until-interrupted "
        "and --report");
  }
  const VisualMap header = ReadMap(flags.add_experience_to);
  const std::string map_file = (fs::path(flags.add_experience_to) / kMapFileName).string();
  const std::string map_matcher =
      MatcherOptionsFromJson(
          RecordedOptionsFromJson(header.options_json, "map '" + map_file + "': options").matcher_json, map_file)
          .type;
  if (flags.matcher_given && flags.matcher.type != map_matcher) {
    throw InputError("the map '" + flags.add_experience_to + "' was built with --matcher " + map_matcher +
                     ", and its experiences are matched as its key images are; drop --matcher " + flags.matcher.type);
  }
  FrameSourceOptions source_options = flags.source.Resolve();
  const std::unique_ptr<FrameSource> source = OpenFrameSource(flags.input, source_options);
  AddExperienceOptions options = flags.experience;
  options.run.show_progress = spdlog::should_log(spdlog::level::info);
  const AddExperienceSummary added = AddExperience(flags.add_experience_to, *source, flags.input, options);
  std::cout << fmt::format("experience      {} of map {}\n", added.experience.id, flags.add_experience_to)
            << fmt::format("frames          {} ({} lost)\n", added.frames, added.lost)
            << fmt::format("views           {} of {} key images\n", added.experience.views.size(),
                           added.num_key_images);
}

void RunBuild(const BuildFlags& flags) {
  if (!flags.add_experience_to.empty()) return RunAddExperience(flags);
  if (flags.acceptance_given) {
    throw InputError(
        "--acceptance, --max-log10-nfa, --min-verified and --min-similarity say when a repeat run's "
        "frames localize; they go with --add-experience-to MAP");
  }
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
    throw InputError(
        "--snapshot-every and --until-interrupted build the map frame by frame, and --search bisect "
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
  command->add_option("--add-experience-to", flags->add_experience_to,
                      "Add the input, a repeat run of the route, to this map as another experience: each key image "
                      "gains the frame that localized at it best (docs/experiences.md)");
  // When a frame of the repeat run is seen at a key image, as `vmap localize` decides it (localize.md).
  LocalizerOptions& localizer = flags->experience.localizer;
  flags->option_flags
      .Record("acceptance",
              command->add_option_function<std::string>(
                  "--acceptance",
                  [&localizer](const std::string& rule) { localizer.acceptance = ParseAcceptanceRule(rule); },
                  "--add-experience-to: when a repeat frame is seen at a key image, as vmap localize "
                  "decides it: chance or counts"))
      ->default_str(AcceptanceRuleName(localizer.acceptance));
  flags->option_flags
      .AddOption(command, "--max-log10-nfa", localizer.max_log10_nfa, "max_log10_nfa",
                 "--add-experience-to, --acceptance chance: accept when log10 of the number of false alarms is at "
                 "most this")
      ->capture_default_str();
  flags->option_flags
      .AddOption(command, "--min-verified", localizer.min_verified, "min_verified",
                 "--add-experience-to, --acceptance counts: verified matches a frame needs")
      ->capture_default_str();
  flags->option_flags
      .AddOption(command, "--min-similarity", localizer.min_similarity, "min_similarity",
                 "--add-experience-to, --acceptance counts: S a frame needs")
      ->capture_default_str();
  command->callback([flags, command] {
    flags->matcher_given = command->count("--matcher") > 0;
    flags->acceptance_given = command->count("--acceptance") + command->count("--max-log10-nfa") +
                                  command->count("--min-verified") + command->count("--min-similarity") >
                              0;
    flags->option_flags.Run([&] { RunBuild(*flags); });
  });
}

}  // namespace vmap::cli
