#include "vmap/pipelines/simulate_pipeline.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>

#include <fmt/format.h>

#include "vmap/control/taught_route.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/stopwatch.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/build_pipeline.h"
#include "vmap/pipelines/localize_odometry.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/simulation/simulation_output.h"
#include "vmap/simulation/teach_run.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// The procedural textures do not change with the seed: the seed varies the trials, not the world.
constexpr unsigned kTextureSeed = 20261128;

// A report folder this pipeline wrote: report.html and top_view.png, nothing else.
std::string WhyNotASimulationReport(const fs::path& directory) {
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
    const std::string name = entry.path().filename().string();
    if (name != "report.html" && name != "top_view.png")
      return "it holds '" + name + "', which vmap simulate never writes";
  }
  return ec ? "it cannot be listed: " + ec.message() : "";
}

// The files the simulation reads, which no output may replace: the texture folders and a route's CSV.
std::vector<std::string> SimulationFilesRead(const SimulationOptions& options) {
  std::vector<std::string> files;
  for (const std::string& path : {options.teach_textures, options.repeat_textures}) {
    if (!path.empty()) files.push_back(path);
  }
  if (FindEnum(kRouteShapeNames, options.route) == std::nullopt) files.push_back(options.route);
  return files;
}

// What the map's folder may replace: a vmap map that holds none of the files the simulation reads.
OutputPolicy MapPolicy(const SimulatePipelineOptions& options) {
  std::vector<std::string> files_read = SimulationFilesRead(options.simulation);
  const std::vector<std::string> matcher_files = options.matcher.FilesRead();
  files_read.insert(files_read.end(), matcher_files.begin(), matcher_files.end());
  return MapOutputPolicy(files_read);
}

// Whether the folders `a` and `b`, existing or not, are the same or one lies inside the other.
bool OneHoldsTheOther(const fs::path& a, const fs::path& b) {
  const auto resolved = [](const fs::path& path) {
    std::error_code ec;
    const fs::path full = fs::weakly_canonical(fs::absolute(path), ec);
    return full.has_filename() ? full : full.parent_path();  // "R/" as "R"
  };
  const fs::path first = resolved(a), second = resolved(b);
  const auto prefix_of = [](const fs::path& outer, const fs::path& inner) {
    return std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end()).first == outer.end();
  };
  return prefix_of(first, second) || prefix_of(second, first) || IsSameOrInside(a, b) || IsSameOrInside(b, a);
}

// Where a map nobody asked to keep is built: never committed, it lives in the temporary folder AtomicOutputDirectory
// makes of this name, one of its own per run (.vmap-simulate-map.partial-PID-N), also when runs share a process. One
// name for every run, so that each removes those a killed run left (RemoveStaleTemporaries).
fs::path TemporaryMapFolder() { return fs::temp_directory_path() / "vmap-simulate-map"; }

}  // namespace

void SimulatePipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section(kOutputSection);
  visitor.Visit(OptionField{"json", "--json", "Write the run (options, summary, every trial) to this JSON file"}
                    .HideDefault()
                    .NotRecorded(),
                json);
  visitor.Visit(OptionField{"report", "--report", "Write an HTML report of the run into this directory"}
                    .HideDefault()
                    .NotRecorded(),
                report);
  visitor.Visit(OptionField{"map", "--map", "Keep the teach run's map in this directory"}.HideDefault().NotRecorded(),
                map);
  visitor.VisitNested("", simulation);
  visitor.VisitNested("", matcher);
}

void SimulatePipelineOptions::Check() const {
  simulation.Check();
  matcher.Check();
}

std::unique_ptr<PreparedTrials> PrepareTrials(const SimulationOptions& options, const MatcherOptions& matcher_options,
                                              const fs::path& map_directory, const std::function<void()>& after_frame) {
  // 1. Everything that can be refused, before any work.
  options.Check();
  matcher_options.Check();
  auto prepared = std::make_unique<PreparedTrials>();
  prepared->route = LoadSimulatedRoute(options);
  const std::vector<cv::Mat> teach_images =
      options.teach_textures.empty()
          ? ProceduralTextures(TexturesToCover(prepared->route.corridor.length(), options.corridor), kTextureSeed)
          : ReadTextureFolder(options.teach_textures, "teach_textures");
  const std::vector<cv::Mat> repeat_images = options.repeat_textures.empty()
                                                 ? std::vector<cv::Mat>{}
                                                 : ReadTextureFolder(options.repeat_textures, "repeat_textures");

  // 2. The worlds: the repeat world shows the repeat textures in the teach world's panels.
  prepared->teach_world.emplace(prepared->route.corridor, options.corridor, teach_images);
  prepared->repeat_world.emplace(repeat_images.empty() ? *prepared->teach_world
                                                       : prepared->teach_world->WithImages(repeat_images));

  // 3. The teach run, its frames rendered as the build pipeline reads them, and its map built as `vmap build`
  //    builds one (τ the matcher's).
  const auto start = std::chrono::steady_clock::now();
  const TeachRun teach = PlanTeachRun(prepared->route, options);
  BuildPipelineOptions build;
  build.input = "simulated teach run (" + prepared->route.name + ")";
  build.output = map_directory.string();
  build.matcher = matcher_options;
  build.map.show_progress = false;
  build.map.after_frame = after_frame;
  RenderedFrameSource frames(*prepared->teach_world, options.camera, teach.poses, teach.seconds_per_frame, build.input);
  RunBuildPipeline(build, &frames, SimulationFilesRead(options));
  prepared->teach_frames = static_cast<int>(teach.poses.size());
  prepared->teach_seconds = SecondsSince(start);
  prepared->teach_odometry = teach.odometry;

  // 4. The map opened for localization, and the route with its taught profile (from the teach odometry). Each
  //    trial drives its own localizer with the session's options, along the taught route.
  LocalizePipelineOptions localize;
  localize.map = map_directory.string();
  localize.session.localizer = options.localizer;
  prepared->session = std::make_unique<LocalizationSession>(localize);
  const LocalizationMap& map = prepared->session->opened();
  TrialContext& context = prepared->context;
  for (const KeyImage& key : map.map.key_images) context.key_image_poses.push_back(teach.poses.at(key.frame_index));
  context.route = &prepared->route;
  context.world = &*prepared->repeat_world;
  context.map = &map;
  context.taught = MakeTaughtRoute(map.map, {}, teach.odometry);
  context.teach_odometry = teach.odometry;
  context.localizer = prepared->session->localizer_options();
  context.localizer.route = context.taught.keys;
  context.teach_duration = teach.odometry.back().timestamp;
  context.options = options;
  context.after_frame = after_frame;
  // 5. The teach run's odometry beside its map, as a robot's teach run writes it (the ROS node's), so that a map kept
  //    (--map) repeats with its taught profile and the localizer's pace; written once the trials' session is open,
  //    which reads the map as it was built.
  WriteTeachOdometry(map_directory, teach.odometry);
  return prepared;
}

void CheckSimulateOutputs(const SimulatePipelineOptions& options) {
  // None may overwrite the route, the textures or each other (the JSON is written last, so it may not land on the
  // map's files or in the report's folder).
  options.Check();
  const SimulationOptions& simulation = options.simulation;
  std::vector<std::vector<OutputInput>> inputs = {NamedInput(simulation.teach_textures, "--teach-textures"),
                                                  NamedInput(simulation.repeat_textures, "--repeat-textures"),
                                                  NamedInput(options.report, "the report folder")};
  if (FindEnum(kRouteShapeNames, simulation.route) == std::nullopt)
    inputs.push_back(NamedInput(simulation.route, "--route"));
  if (!options.map.empty()) inputs.push_back(MapInputs(options.map));
  CheckOutputs({{options.json, "json"}}, inputs);
  // The map kept and the report are folders of their own: the one committed second would replace or refuse the
  // other, after all the work.
  if (!options.map.empty() && !options.report.empty() && OneHoldsTheOther(options.map, options.report)) {
    throw OptionError("map",
                      "'" + options.map + "' and the report folder '" + options.report +
                          "' lie one in the other; give two separate folders",
                      {"report"});
  }
  // The map's folder: refused now when it is not vmap's or holds what the simulation reads, not after the teach run.
  if (!options.map.empty()) CheckOutputDirectory(options.map, MapPolicy(options));
}

SimulatePipelineResult RunSimulatePipeline(const SimulatePipelineOptions& options,
                                           const std::function<void(const TrialResult&)>& on_trial) {
  const auto start = std::chrono::steady_clock::now();
  const SimulationOptions& simulation = options.simulation;

  // 1. The options and the outputs.
  CheckSimulateOutputs(options);

  // 2. The folders, claimed before any work: the report's, and the map's (kept only with options.map; until the
  //    end it is built in a hidden folder beside it, which goes if the run fails).
  OutputPolicy report_policy;
  report_policy.why_not_ours = WhyNotASimulationReport;
  report_policy.kind = "a vmap simulate report";
  for (const std::string& file : SimulationFilesRead(simulation)) report_policy.inputs.emplace_back(file);
  std::unique_ptr<AtomicOutputDirectory> report;
  if (!options.report.empty()) report = std::make_unique<AtomicOutputDirectory>(options.report, report_policy);
  AtomicOutputDirectory map_directory(options.map.empty() ? TemporaryMapFolder() : fs::path(options.map),
                                      MapPolicy(options));

  // 3-4. The route, the worlds, the teach run and its map, the trials' context.
  const std::unique_ptr<PreparedTrials> prepared =
      PrepareTrials(simulation, options.matcher, map_directory.path(), options.after_frame);
  const TrialContext& context = prepared->context;
  SimulatePipelineResult result;
  SimulationResult& run = result.simulation;
  run.route = prepared->route;
  run.teach_frames = prepared->teach_frames;
  run.teach_seconds = prepared->teach_seconds;
  run.matcher = prepared->map().matcher->name();
  run.key_images = static_cast<int>(prepared->map().map.key_images.size());
  run.key_image_poses = context.key_image_poses;

  // 5. The trials, independent of each other.
  run.trials = RunTrials(context, simulation.trials, simulation.threads, on_trial);
  run.summary = Summarize(run.trials);
  run.seconds = SecondsSince(start);

  // 6. The outputs: all written before any is put in place, so that a failure while writing one (a full disk)
  // leaves every output of an earlier run as it was.
  if (report) WriteSimulationReport(run, simulation, report->path());
  std::optional<PendingFile> json_file;
  if (!options.json.empty()) json_file.emplace(options.json, SimulationJson(run, simulation).dump() + "\n");
  if (!options.map.empty()) map_directory.Commit();
  if (report) report->Commit();
  if (json_file) json_file->Commit();
  return result;
}

}  // namespace vmap
