#include "vmap/simulation/closed_loop.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include "vmap/core/parallel_for.h"

namespace vmap {

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
  if (with_second_half > 0) {
    summary.mean_lateral_rms_second_half /= with_second_half;
  } else {  // no figure rather than 0 m, which would read as a perfect run
    summary.mean_lateral_rms_second_half = summary.worst_lateral_rms_second_half =
        std::numeric_limits<double>::quiet_NaN();
  }
  summary.share_converged /= std::max(1, summary.trials);
  summary.success_rate = static_cast<double>(summary.successes) / std::max(1, summary.trials);
  if (summary.frames > 0) summary.mean_step_seconds = step_total / summary.frames;
  if (render_total > 0.0) summary.render_frames_per_second = summary.frames / render_total;
  return summary;
}

std::vector<TrialResult> RunTrials(const TrialContext& context, int count, int threads,
                                   const std::function<void(const TrialResult&)>& on_trial) {
  std::vector<TrialResult> trials(count);
  std::mutex mutex;
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  ParallelFor(trials.size(), threads, [&](size_t i) {
    TrialResult trial = RunTrial(context, static_cast<int>(i));
    std::lock_guard<std::mutex> lock(mutex);
    trials[i] = std::move(trial);
    if (on_trial) on_trial(trials[i]);
  });
  return trials;
}

}  // namespace vmap
