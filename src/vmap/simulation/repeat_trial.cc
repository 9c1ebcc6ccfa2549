#include "vmap/simulation/repeat_trial.h"

#include <chrono>

#include "vmap/core/stopwatch.h"
#include "vmap/simulation/trial_run.h"

namespace vmap {

TrialResult RunTrial(const TrialContext& context, int index) {
  TrialRun run(context, index);
  Localizer localizer(context.map->map, context.map->keys, *context.map->matcher, context.localizer);
  // The robot's odometry paces the belief as it does on the robot (the ROS node's repeat run).
  if (context.options.use_odometry) localizer.PaceByTeachOdometry(context.teach_odometry);
  RouteController controller(context.taught, context.options.controller);
  while (run.Continues()) {
    Frame frame = run.Render();
    if (context.options.use_odometry) frame.odometry = run.odometry();
    if (context.after_frame) context.after_frame();
    const auto step_start = std::chrono::steady_clock::now();
    const auto features = context.map->matcher->ExtractFrame(frame.gray, frame.color);
    const LocalizationResult localization = localizer.Localize(frame, *features);
    const OdometrySample odometry = run.odometry();
    const ControlStep step =
        controller.Update(run.time(), localization, context.options.use_odometry ? &odometry : nullptr);
    run.Record(localization, step, SecondsSince(step_start));
    // At the goal the controller slows the robot down within its decelerations: the robot stops where that ends.
    if (step.state == ControllerState::kReachedGoal && step.command.stops()) break;
    run.Drive(step.command);
  }
  return run.Finish();
}

}  // namespace vmap
