#include "vmap/simulation/repeat_trial.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "vmap/control/guidance_signals.h"
#include "vmap/simulation/robot.h"
#include "vmap/simulation/teach_run.h"

namespace vmap {

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void Summarize(TrialResult& trial, double route_length) {
  double sum_squares = 0.0;
  int second_half = 0;
  trial.lateral_max = 0.0;
  double max_second = 0.0;
  for (const TrialSample& sample : trial.samples) {
    trial.lateral_max = std::max(trial.lateral_max, std::abs(sample.lateral));
    if (sample.s >= 0.5 * route_length) {
      sum_squares += sample.lateral * sample.lateral;
      max_second = std::max(max_second, std::abs(sample.lateral));
      ++second_half;
    }
  }
  if (second_half > 0) {
    trial.lateral_rms_second_half = std::sqrt(sum_squares / second_half);
    trial.lateral_max_second_half = max_second;
  }
  for (size_t i = trial.samples.size(); i-- > 0;) {
    if (std::abs(trial.samples[i].lateral) > 0.1) {
      if (i + 1 < trial.samples.size()) trial.settled_at = trial.samples[i + 1].s;
      break;
    }
    if (i == 0) trial.settled_at = trial.samples[0].s;
  }
}

}  // namespace

TrialResult RunTrial(const TrialContext& context, int index) {
  const SimulationOptions& options = context.options;
  const SimulatedRoute& route = *context.route;
  TrialResult trial;
  trial.index = index;
  std::mt19937 rng(static_cast<unsigned>(options.seed) * 1000003u + static_cast<unsigned>(index));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  trial.start_lateral = options.max_lateral_offset * unit(rng);
  trial.start_heading_deg = options.max_heading_offset_deg * unit(rng);
  const Pose2d start = route.path.At(0.0);
  Pose2d pose = start;
  pose.x -= std::sin(start.yaw) * trial.start_lateral;
  pose.y += std::cos(start.yaw) * trial.start_lateral;
  pose.yaw = WrapAngle(start.yaw + trial.start_heading_deg * M_PI / 180.0);
  DifferentialDriveRobot robot(pose, options.noise, static_cast<unsigned>(rng()));

  Localizer localizer(context.map->map, context.map->keys, *context.map->matcher, context.localizer);
  RouteController controller(context.taught, options.controller);
  const double dt = 1.0 / options.rate;
  const double time_limit = options.time_limit_factor * context.teach_duration + 20.0;
  const double room = 0.5 * options.corridor.width - options.robot_radius;
  const Pose2d goal = route.path.At(route.path.length());
  double s = 0.0, corridor_s = route.path_start;
  double step_total = 0.0, render_total = 0.0;
  for (int k = 0;; ++k) {
    const double time = k * dt;
    const Pose2d truth = robot.pose();
    // Where the robot is on the route and in the corridor, searched near where it was (a loop passes twice).
    const RoutePath::Projection on_route = route.path.Project({truth.x, truth.y}, s - 1.0, s + 2.0);
    const RoutePath::Projection in_corridor =
        route.corridor.Project({truth.x, truth.y}, corridor_s - 1.0, corridor_s + 2.0);
    s = on_route.s;
    corridor_s = in_corridor.s;
    if (std::abs(in_corridor.lateral) > room) {
      trial.end = "left the corridor";
      break;
    }
    if (time > time_limit) {
      trial.end = "time limit";
      break;
    }
    const auto render_start = std::chrono::steady_clock::now();
    const Frame frame = RenderFrame(*context.world, options.camera, truth, k, time);
    render_total += Seconds(render_start);
    const auto step_start = std::chrono::steady_clock::now();
    const auto features = context.map->matcher->ExtractFrame(frame.gray, frame.color);
    const LocalizationResult localization = localizer.Localize(frame, *features);
    const OdometrySample odometry = robot.odometry();
    const ControlStep step = controller.Update(time, localization, options.use_odometry ? &odometry : nullptr);
    const double step_seconds = Seconds(step_start);
    step_total += step_seconds;
    trial.max_step_seconds = std::max(trial.max_step_seconds, step_seconds);

    TrialSample sample;
    sample.time = time;
    sample.pose = truth;
    sample.s = s;
    sample.lateral = on_route.lateral;
    sample.status = localization.status;
    sample.key = localization.key;
    sample.state = step.state;
    sample.steering = step.steering;
    sample.heading_offset = step.heading_offset;
    sample.bearing = step.bearing;
    sample.line_angle = step.line_angle;
    sample.lateral_estimate = step.lateral_estimate;
    sample.observation = step.observation;
    sample.translation_sigma_deg = TargetComparison(localization).translation_sigma_deg;
    sample.target_verified = TargetComparison(localization).num_verified;
    if (step.target_key >= 0 && step.target_key < static_cast<int>(context.key_image_poses.size())) {
      // The servo's angles as they truly are: alpha, the bearing of the key image's position from the robot's
      // heading, and beta, the key image's heading minus that bearing's direction.
      const Pose2d& key = context.key_image_poses[step.target_key];
      const double direction = std::atan2(key.y - truth.y, key.x - truth.x);
      sample.true_bearing = WrapAngle(direction - truth.yaw);
      sample.true_line_angle = WrapAngle(key.yaw - direction);
    }
    sample.command = step.command;
    sample.step_seconds = step_seconds;
    trial.samples.push_back(sample);
    ++trial.frames;
    if (localization.status != LocalizationStatus::kTracking &&
        localization.status != LocalizationStatus::kRelocalized) {
      ++trial.frames_lost;
    }
    if (step.state == ControllerState::kReachedGoal) {
      trial.reached_goal = true;
      trial.end = "reached goal";
      break;
    }
    robot.Step(step.command, dt);
  }
  const Pose2d last = robot.pose();
  trial.final_error = std::hypot(last.x - goal.x, last.y - goal.y);
  trial.success = trial.reached_goal && trial.final_error <= options.goal_tolerance;
  trial.duration = robot.time();
  if (trial.frames > 0) {
    trial.mean_step_seconds = step_total / trial.frames;
    trial.mean_render_seconds = render_total / trial.frames;
  }
  Summarize(trial, route.path.length());
  return trial;
}

}  // namespace vmap
