#include "vmap/pipelines/build_pipeline.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/interrupt.h"
#include "vmap/map/map_io.h"
#include "vmap/map/map_writer.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/map_builder.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/report/html_report.h"
#include "vmap/sources/read_ahead_source.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

constexpr double kMaxSnapshotEvery = 86400.0;  // seconds: a day

// "orb 0.5, aliked 0.7, ...": each registered matcher's default τ, for --help.
std::string DefaultTaus() {
  std::string text;
  for (const auto& model : MatcherModels()) {
    text += (text.empty() ? "" : ", ") + model.name + " " + fmt::format("{}", model.default_tau);
  }
  return text;
}

// SIGINT ends the input (InputEndRequested) while a live build runs, and no longer once it is over.
class EndInputOnSigintWhile {
 public:
  explicit EndInputOnSigintWhile(bool enabled) : enabled_(enabled) {
    if (enabled_) EndInputOnSigint(true);
  }
  ~EndInputOnSigintWhile() {
    if (enabled_) EndInputOnSigint(false);
  }
  EndInputOnSigintWhile(const EndInputOnSigintWhile&) = delete;
  EndInputOnSigintWhile& operator=(const EndInputOnSigintWhile&) = delete;

 private:
  bool enabled_;
};

// Streams the input through a MapBuilder: snapshots while it runs, the end of the input when the host asks.
VisualMap BuildStreaming(const BuildPipelineOptions& pipeline, FrameSource& input, const Matcher& matcher,
                         const MapBuilderOptions& options, const AtomicOutputDirectory& directory,
                         const std::string& options_json, const std::vector<std::string>& files_read,
                         bool* interrupted) {
  std::optional<SnapshotTarget> snapshots;
  if (pipeline.snapshot_every > 0) {
    snapshots = SnapshotTarget{directory.final_path(), MapOutputPolicy(files_read, pipeline.files_beside_map),
                               pipeline.write_beside_map};
    snapshots->policy.keep_if_commit_fails = false;  // the next snapshot, or the map itself, takes its place
  }
  MapWriter writer(directory.path(), snapshots);
  // Decoded on a thread of its own, while this one runs Algorithm 1 (see BuildMap).
  ReadAheadSource source(input, options.prefetch_frames);
  MapBuilder builder(source, matcher, options, &writer, options_json);
  using Clock = std::chrono::steady_clock;
  auto last_snapshot = Clock::now();
  std::string snapshot_problem;  // why the last snapshot failed; "" when it was written
  *interrupted = false;
  for (;;) {
    if (pipeline.until_interrupted && InputEndRequested()) {
      *interrupted = true;
      break;
    }
    std::optional<Frame> frame = source.Next();
    if (!frame) {
      *interrupted = pipeline.until_interrupted && InputEndRequested();
      break;
    }
    builder.Add(std::move(*frame));
    if (options.after_frame) options.after_frame();
    // Between frames: a source that waits long for its next frame delays the snapshot as long.
    if (snapshots && std::chrono::duration<double>(Clock::now() - last_snapshot).count() >= pipeline.snapshot_every) {
      // A snapshot that cannot be written (the folder unwritable for a while, the disk full) is a warning, once
      // for each new reason: ending the run for it would lose every frame of a drive that cannot be made again.
      std::string problem;
      try {
        builder.Snapshot();
        spdlog::debug("snapshot written to {}", directory.final_path().string());
      } catch (const InputError& error) {
        problem = error.what();
      } catch (const std::filesystem::filesystem_error& error) {
        problem = error.what();
      }
      if (!problem.empty() && problem != snapshot_problem) {
        spdlog::warn("snapshot not written; the run goes on and tries again every {} s: {}", pipeline.snapshot_every,
                     problem);
      } else if (problem.empty() && !snapshot_problem.empty()) {
        spdlog::info("snapshot written to {} again", directory.final_path().string());
      }
      snapshot_problem = problem;
      last_snapshot = Clock::now();
    }
  }
  if (*interrupted) spdlog::info("input ended by SIGINT: finishing the map from the frames seen");
  return builder.Finish(*interrupted ? CoverageEnd::kInterrupted : CoverageEnd::kInputEnded);
}

}  // namespace

void BuildPipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  static const std::string tau_help =
      "Similarity threshold tau in (0, 1]: lower keeps fewer key images (default: the matcher's, " + DefaultTaus() +
      ")";
  visitor.Visit(
      OptionField{"input", "input", "Video file, image folder, TUM RGB-D, EuRoC or KITTI sequence"}.Positional(),
      input);
  visitor.Section(kOutputSection);
  visitor.Visit(OptionField{"output", "-o,--output", "Map directory to write (default: <input name>_map)"}
                    .HideDefault()
                    .NotRecorded(),
                output);
  visitor.VisitNested("", source);
  visitor.VisitNested("", matcher);
  // The verifier's options first, as `vmap build --help` has always listed them.
  visitor.VisitNested("verifier", map.verifier);
  visitor.Section("Key images");
  visitor.Visit(OptionField{"tau", "-t,--tau", tau_help.c_str()}.HideDefault().NotRecorded(), tau);
  visitor.VisitNested("", map, Nesting{false, {"verifier"}});
  visitor.Section(kOutputSection);
  visitor.Visit(OptionField{"report", "--report", "Also write report.html into the map directory"}.NotRecorded(),
                report);
  visitor.Visit(OptionField{"snapshot_every", "--snapshot-every",
                            "Seconds between snapshots: the map so far, written to the output directory while the "
                            "run goes on (0 = none)"}
                    .Within(0, kMaxSnapshotEvery)
                    .Meaning("0: none")
                    .NotRecorded(),
                snapshot_every);
  visitor.Visit(OptionField{"until_interrupted", "--until-interrupted",
                            "SIGINT (Ctrl-C) ends the input and the map is finished from the frames seen (a second "
                            "SIGINT aborts); for cameras and streams"}
                    .NotRecorded(),
                until_interrupted);
}

MapBuilderOptions BuildPipelineOptions::ResolvedMapOptions() const {
  MapBuilderOptions resolved = map;
  resolved.key_images.tau = tau ? *tau : DefaultTau(matcher.type);
  return resolved;
}

fs::path BuildPipelineOptions::OutputDirectory() const {
  if (!output.empty()) return output;
  // Named after the input's last component, however it was written: "run1/" (as tab completion writes it) and
  // "run1/." are run1, not "" (every such input's map was "_map", one replacing the other) or ".".
  fs::path named = fs::path(input).lexically_normal();
  if (named.filename().empty()) named = named.parent_path();
  if (named.filename().empty() || named.filename() == "." || named.filename() == "..") {
    std::error_code ec;
    named = fs::absolute(input, ec).lexically_normal();
    if (named.filename().empty()) named = named.parent_path();
  }
  return fs::path(named.filename().stem().string() + "_map");
}

void BuildPipelineOptions::Check() const {
  source.Check();
  matcher.Check();  // first: τ's default is the matcher's
  try {
    ResolvedMapOptions().Check();
  } catch (const OptionError& error) {
    // τ is given as `tau`, whatever field of the builder's it becomes.
    if (error.path() == "key_images.tau") throw OptionError("tau", error.problem());
    throw;
  }
  if (!(snapshot_every >= 0.0 && snapshot_every <= kMaxSnapshotEvery)) {
    throw OptionError("snapshot_every",
                      fmt::format("must be 0 (no snapshots) to {} seconds", static_cast<int>(kMaxSnapshotEvery)));
  }
  const bool streaming = snapshot_every > 0 || until_interrupted;
  if (streaming && ResolveKeySearch(ResolvedMapOptions()) == KeySearch::kBisect) {
    throw OptionError("key_search",
                      "bisect reads ahead, while snapshot_every and until_interrupted build the map frame by frame; "
                      "leave it out",
                      {"snapshot_every", "until_interrupted"});
  }
}

std::vector<std::string> BuildPipelineOptions::FilesRead() const {
  std::vector<std::string> files = matcher.FilesRead();
  files.push_back(input);
  // --camera is a file, or intrinsics given as numbers, or "none".
  std::error_code ec;
  if (!source.camera.empty() && std::filesystem::exists(source.camera, ec)) files.push_back(source.camera);
  return files;
}

namespace {

// Said before the work, so that a user who wanted to keep them can stop: the experiences of a map the build replaces
// are dropped with it (their views were matched to its key images, which the new map's are not).
void WarnOfExperiencesReplaced(const std::string& map_directory) {
  const ContainedJson map_json = ReadContainedJson(map_directory, kMapFileName, kMaxMapJsonBytes, kMaxMapJsonValues);
  if (!map_json.document || !map_json.document->is_object()) return;
  const auto experiences = map_json.document->find("experiences");
  if (experiences == map_json.document->end() || !experiences->is_array() || experiences->empty()) return;
  spdlog::warn(
      "'{}' holds {} experience(s) of other runs, which the new map replaces with the old one: add them again "
      "with `vmap build RUN --add-experience-to {}` once it is built",
      map_directory, experiences->size(), map_directory);
}

}  // namespace

BuildPipelineResult RunBuildPipeline(const BuildPipelineOptions& pipeline, FrameSource* given_source,
                                     const std::vector<std::string>& source_files) {
  // 1. The options, τ resolved; the progress line where the log shows information.
  pipeline.Check();
  MapBuilderOptions options = pipeline.ResolvedMapOptions();
  options.show_progress = options.show_progress && spdlog::should_log(spdlog::level::info);
  BuildPipelineResult result;
  result.directory = pipeline.OutputDirectory();

  // 2. The output, claimed before any work: one that is not vmap's, or that holds the input, is refused here.
  std::vector<std::string> files_read = pipeline.FilesRead();
  files_read.insert(files_read.end(), source_files.begin(), source_files.end());
  AtomicOutputDirectory directory(result.directory, MapOutputPolicy(files_read, pipeline.files_beside_map));
  WarnOfExperiencesReplaced(result.directory);

  // 3. The matcher (a deep model loads its weights here).
  const std::unique_ptr<Matcher> matcher = CreateMatcher(pipeline.matcher);

  // 4. The input.
  FrameSourceOptions source_options = pipeline.source;
  const EndInputOnSigintWhile live_end(pipeline.until_interrupted);
  if (pipeline.until_interrupted) source_options.stop_requested = [] { return InputEndRequested(); };
  std::unique_ptr<FrameSource> opened;
  if (given_source == nullptr) opened = OpenFrameSource(pipeline.input, source_options);
  FrameSource& source = given_source != nullptr ? *given_source : *opened;

  // 5. The map.
  const std::string options_json = DescribeMapOptions(*matcher, options, source_options);
  result.map = ResolveKeySearch(options) == KeySearch::kBisect
                   ? BuildMap(source, *matcher, options, directory.path(), options_json)
                   : BuildStreaming(pipeline, source, *matcher, options, directory, options_json, files_read,
                                    &result.interrupted);

  // A tau too high for the input or the matcher keeps most frames (XFeat's default on rccar_room: 290 of 329): the map
  // is then nearly the run itself, as large and as slow to localize against. Said, with what to do; --tau 1 asks it.
  const size_t key_images = result.map.key_images.size();
  const int frames = result.map.num_frames;
  if (options.key_images.tau < 1.0 && frames >= 20 && 2 * key_images > static_cast<size_t>(frames)) {
    spdlog::warn(
        "{} of {} frames became key images at tau {}: the map is nearly the run itself; a lower --tau keeps "
        "fewer (vmap sweep INPUT --thresholds 0.2:0.8:0.1 shows how many each keeps)",
        key_images, frames, options.key_images.tau);
  }

  // 6. The report, and the host's files.
  if (pipeline.report) WriteMapReport(directory.path());
  if (pipeline.write_beside_map) pipeline.write_beside_map(directory.path());

  // 7. The map in place.
  directory.Commit();
  return result;
}

}  // namespace vmap
