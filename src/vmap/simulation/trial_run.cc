#include "vmap/simulation/trial_run.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "vmap/control/guidance_signals.h"
#include "vmap/control/taught_route.h"
#include "vmap/core/stopwatch.h"
#include "vmap/simulation/teach_run.h"

namespace vmap {

namespace {

// The trial's start: the route's start offset sideways and turned, drawn from the seed and the index, and the seed
// of the robot's noise drawn after them.
struct TrialStart {
  double lateral = 0.0;
  double heading_deg = 0.0;
  Pose2d pose;
  unsigned noise_seed = 0;
};

TrialStart DrawStart(const TrialContext& context, int index) {
  const SimulationOptions& options = context.options;
  std::mt19937 rng(static_cast<unsigned>(options.seed) * 1000003u + static_cast<unsigned>(index));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  TrialStart start;
  start.lateral = options.max_lateral_offset * unit(rng);
  start.heading_deg = options.max_heading_offset_deg * unit(rng);
  const Pose2d route_start = context.route->path.At(0.0);
  start.pose = route_start;
  start.pose.x -= std::sin(route_start.yaw) * start.lateral;
  start.pose.y += std::cos(route_start.yaw) * start.lateral;
  start.pose.yaw = WrapAngle(route_start.yaw + start.heading_deg * M_PI / 180.0);
  start.noise_seed = static_cast<unsigned>(rng());
  return start;
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

TrialRun::TrialRun(const TrialContext& context, int index)
    : context_(context), robot_([&] {
        const TrialStart start = DrawStart(context, index);
        trial_.index = index;
        trial_.start_lateral = start.lateral;
        trial_.start_heading_deg = start.heading_deg;
        return DifferentialDriveRobot(start.pose, context.options.noise, start.noise_seed);
      }()) {
  const SimulationOptions& options = context.options;
  dt_ = 1.0 / options.rate;
  time_limit_ = options.time_limit_factor * context.teach_duration + 20.0;
  room_ = 0.5 * options.corridor.width - options.robot_radius;
  reach_ = std::max(1.0, 2.0 * options.controller.max_speed * dt_);
  corridor_s_ = context.route->path_start;
}

bool TrialRun::Continues() {
  if (!trial_.end.empty()) return false;
  const SimulatedRoute& route = *context_.route;
  const Pose2d& truth = robot_.pose();
  // Where the robot is on the route and in the corridor, searched near where it was (a loop passes twice).
  // Within 2 m ahead, whatever the speed, a step of 5 m "left the corridor" on the centre line.
  const RoutePath::Projection on_route = route.path.Project({truth.x, truth.y}, s_ - reach_, s_ + reach_ + 1.0);
  const RoutePath::Projection in_corridor =
      route.corridor.Project({truth.x, truth.y}, corridor_s_ - reach_, corridor_s_ + reach_ + 1.0);
  s_ = on_route.s;
  corridor_s_ = in_corridor.s;
  lateral_ = on_route.lateral;
  if (std::abs(in_corridor.lateral) > room_) {
    trial_.end = "left the corridor";
  } else if (time() > time_limit_) {
    trial_.end = "time limit";
  }
  return trial_.end.empty();
}

Frame TrialRun::Render() {
  const auto render_start = std::chrono::steady_clock::now();
  Frame frame = RenderFrame(*context_.world, context_.options.camera, robot_.pose(), step_, time());
  render_total_ += SecondsSince(render_start);
  return frame;
}

void TrialRun::Record(const LocalizationResult& localization, const ControlStep& step, double step_seconds) {
  step_total_ += step_seconds;
  trial_.max_step_seconds = std::max(trial_.max_step_seconds, step_seconds);
  const Pose2d& truth = robot_.pose();
  TrialSample sample;
  sample.time = time();
  sample.pose = truth;
  sample.s = s_;
  sample.lateral = lateral_;
  sample.status = localization.status;
  sample.key = localization.key;
  sample.state = step.state;
  sample.steering = step.steering;
  sample.heading_offset = step.heading_offset;
  sample.bearing = step.bearing;
  sample.line_angle = step.line_angle;
  sample.lateral_estimate = step.lateral_estimate;
  sample.heading_error_estimate = step.heading_error_estimate;
  sample.arc_estimate = step.arc_estimate;
  sample.observation = step.observation;
  const KeyComparison& target = TargetComparison(localization);
  sample.translation_sigma_deg = target.translation_sigma_deg;
  sample.target_verified = target.num_verified;
  if (target.pose.valid) sample.pose_heading = -YawOfCameraRotation(target.pose.R);
  if (localization.translation_known) {
    const TargetBearing measured = BearingToKey(target.pose);
    if (measured.valid) sample.pose_bearing = measured.bearing;
  }
  sample.key_log_scale = ApparentLogScale(localization.to_key.verified);
  if (step.target_key >= 0 && step.target_key < static_cast<int>(context_.key_image_poses.size())) {
    // The servo's angles as they truly are: alpha, the bearing of the key image's position from the robot's
    // heading, and beta, the key image's heading minus that bearing's direction.
    const Pose2d& key = context_.key_image_poses[step.target_key];
    const double direction = std::atan2(key.y - truth.y, key.x - truth.x);
    sample.true_bearing = WrapAngle(direction - truth.yaw);
    sample.true_line_angle = WrapAngle(key.yaw - direction);
  }
  sample.command = step.command;
  sample.step_seconds = step_seconds;
  trial_.samples.push_back(sample);
  ++trial_.frames;
  if (localization.status != LocalizationStatus::kTracking && localization.status != LocalizationStatus::kRelocalized) {
    ++trial_.frames_lost;
  }
  if (step.state == ControllerState::kReachedGoal) {
    trial_.reached_goal = true;
    // The trial ends where the robot stands still: the controller slows it down within its decelerations.
    if (step.command.stops()) trial_.end = "reached goal";
  }
}

void TrialRun::Drive(const VelocityCommand& command) {
  robot_.Step(command, dt_);
  ++step_;
}

TrialResult TrialRun::Finish() {
  const SimulatedRoute& route = *context_.route;
  const Pose2d goal = route.path.At(route.path.length());
  const Pose2d last = robot_.pose();
  trial_.final_error = std::hypot(last.x - goal.x, last.y - goal.y);
  trial_.success = trial_.reached_goal && trial_.final_error <= context_.options.goal_tolerance;
  trial_.duration = robot_.time();
  // The pose that ended the trial (left the corridor, time limit) came after the last frame's: recorded too, as where
  // the last frame's command took the robot, so the samples and the top view show the end that final_error measures.
  if (!trial_.samples.empty() && trial_.samples.back().time < time()) {
    TrialSample end = trial_.samples.back();
    end.time = time();
    end.pose = last;
    end.s = s_;
    end.lateral = lateral_;
    end.step_seconds = 0.0;
    trial_.samples.push_back(end);
  }
  if (trial_.frames > 0) {
    trial_.mean_step_seconds = step_total_ / trial_.frames;
    trial_.mean_render_seconds = render_total_ / trial_.frames;
  }
  Summarize(trial_, route.path.length());
  return trial_;
}

}  // namespace vmap
