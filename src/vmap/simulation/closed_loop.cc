#include "vmap/simulation/closed_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "vmap/control/taught_route.h"
#include "vmap/core/parallel_for.h"
#include "vmap/localization/localization_map.h"
#include "vmap/simulation/corridor_world.h"
#include "vmap/simulation/teach_run.h"

namespace vmap {

namespace {
// The procedural textures do not change with options.seed: the seed varies the trials, not the world.
constexpr unsigned kTextureSeed = 20261128;
}  // namespace

SimulatedRoute LoadSimulatedRoute(const SimulationOptions& options) {
  if (const std::optional<RouteShape> shape = FindEnum(kRouteShapeNames, options.route)) {
    SimulatedRoute route = MakeRoute(*shape);
    CheckCorridor(route.corridor, options.corridor.width, "route " + route.name);
    return route;
  }
  return ReadRouteCsv(options.route, options.corridor.width);
}

SimulationSummary Summarize(const std::vector<TrialResult>& trials) {
  SimulationSummary summary;
  summary.trials = static_cast<int>(trials.size());
  double step_total = 0.0, render_total = 0.0;
  int with_second_half = 0;
  for (const TrialResult& trial : trials) {
    summary.successes += trial.success ? 1 : 0;
    summary.mean_final_error += trial.final_error / std::max<size_t>(1, trials.size());
    if (std::isfinite(trial.lateral_rms_second_half)) {
      summary.mean_lateral_rms_second_half += trial.lateral_rms_second_half;
      summary.worst_lateral_rms_second_half =
          std::max(summary.worst_lateral_rms_second_half, trial.lateral_rms_second_half);
      summary.share_converged += trial.lateral_rms_second_half <= 0.1 ? 1 : 0;
      ++with_second_half;
    }
    summary.frames += trial.frames;
    summary.frames_lost += trial.frames_lost;
    step_total += trial.mean_step_seconds * trial.frames;
    render_total += trial.mean_render_seconds * trial.frames;
    summary.max_step_seconds = std::max(summary.max_step_seconds, trial.max_step_seconds);
  }
  if (with_second_half > 0) summary.mean_lateral_rms_second_half /= with_second_half;
  summary.share_converged /= std::max(1, summary.trials);
  summary.success_rate = static_cast<double>(summary.successes) / std::max(1, summary.trials);
  if (summary.frames > 0) summary.mean_step_seconds = step_total / summary.frames;
  if (render_total > 0.0) summary.render_frames_per_second = summary.frames / render_total;
  return summary;
}

std::unique_ptr<PreparedTrials> PrepareTrials(const SimulationOptions& options, const MatcherOptions& matcher_options,
                                              const std::filesystem::path& map_directory) {
  // 1. Everything that can be refused, before any work.
  options.Check();
  matcher_options.Check();
  auto prepared = std::make_unique<PreparedTrials>();
  prepared->route = LoadSimulatedRoute(options);
  if (options.teach_textures.empty() && !options.repeat_textures.empty()) {
    throw InputError("--repeat-textures replaces the teach textures in another season; give --teach-textures too");
  }
  const std::vector<cv::Mat> teach_images =
      options.teach_textures.empty()
          ? ProceduralTextures(TexturesToCover(prepared->route.corridor.length(), options.corridor), kTextureSeed)
          : ReadTextureFolder(options.teach_textures, "--teach-textures");
  const std::vector<cv::Mat> repeat_images = options.repeat_textures.empty()
                                                 ? std::vector<cv::Mat>{}
                                                 : ReadTextureFolder(options.repeat_textures, "--repeat-textures");

  // 2. The worlds: the repeat world shows the repeat textures in the teach world's panels.
  prepared->teach_world.emplace(prepared->route.corridor, options.corridor, teach_images);
  prepared->repeat_world.emplace(repeat_images.empty() ? *prepared->teach_world
                                                       : prepared->teach_world->WithImages(repeat_images));

  // 3. The teach run and its map, built as `vmap build` builds one.
  const std::unique_ptr<Matcher> matcher = CreateMatcher(matcher_options);
  const TeachRun teach = RunTeach(prepared->route, *prepared->teach_world, options, *matcher,
                                  DefaultTau(matcher_options.type), map_directory);
  prepared->teach_frames = static_cast<int>(teach.poses.size());
  prepared->teach_seconds = teach.seconds;
  prepared->teach_odometry = teach.odometry;

  // 4. The map opened for localization, and the route with its taught profile (from the teach odometry).
  KeyImageStoreOptions store_options;
  prepared->map = OpenLocalizationMap(map_directory, store_options);
  TrialContext& context = prepared->context;
  for (const KeyImage& key : prepared->map.map.key_images)
    context.key_image_poses.push_back(teach.poses.at(key.frame_index));
  context.route = &prepared->route;
  context.world = &*prepared->repeat_world;
  context.map = &prepared->map;
  context.taught = MakeTaughtRoute(prepared->map.map, {}, teach.odometry);
  context.localizer = FollowMap(prepared->map, options.localizer, QueryResize(prepared->map.map, ""));
  context.localizer.route = context.taught.keys;
  context.teach_duration = teach.odometry.back().timestamp;
  context.options = options;
  return prepared;
}

SimulationResult Simulate(const SimulationOptions& options, const MatcherOptions& matcher_options,
                          const std::filesystem::path& map_directory,
                          const std::function<void(const TrialResult&)>& on_trial) {
  const auto start = std::chrono::steady_clock::now();
  // 1-4. The route, the worlds, the teach run and its map, the trials' context.
  const std::unique_ptr<PreparedTrials> prepared = PrepareTrials(options, matcher_options, map_directory);
  const TrialContext& context = prepared->context;
  SimulationResult result;
  result.route = prepared->route;
  result.teach_frames = prepared->teach_frames;
  result.teach_seconds = prepared->teach_seconds;
  result.matcher = prepared->map.matcher->name();
  result.key_images = static_cast<int>(prepared->map.map.key_images.size());
  result.key_image_poses = context.key_image_poses;

  // 5. The trials, independent of each other (each its own localizer, controller and robot).
  result.trials.resize(options.trials);
  std::mutex mutex;
  const int threads =
      options.threads > 0 ? options.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  ParallelFor(result.trials.size(), threads, [&](size_t i) {
    TrialResult trial = RunTrial(context, static_cast<int>(i));
    std::lock_guard<std::mutex> lock(mutex);
    result.trials[i] = std::move(trial);
    if (on_trial) on_trial(result.trials[i]);
  });
  result.summary = Summarize(result.trials);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace vmap
