#pragma once
// One repeat trial's world, stepped from outside: the robot placed at the trial's start (its offsets and noise drawn
// from options.seed and the trial's index), its camera's frame at each control step, its odometry, and what the
// trial measures (where the robot is against the route, leaving the corridor, the time limit, the final error).
// The brain is the caller's: RunTrial (repeat_trial.h) localizes and controls in the same process; the ROS
// simulator node (ros/) publishes the frame and drives with the command a vmap node sends back on cmd_vel.
//
//   TrialRun run(context, index);
//   while (run.Continues()) {
//     Frame frame = run.Render();
//     ... localization, step = controller.Update(run.time(), localization, &run.odometry()) ...
//     run.Record(localization, step, seconds);
//     if (step.state == ControllerState::kReachedGoal) break;
//     run.Drive(step.command);
//   }
//   TrialResult result = run.Finish();

#include <chrono>
#include <string>

#include "vmap/control/route_controller.h"
#include "vmap/simulation/repeat_trial.h"
#include "vmap/simulation/robot.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

class TrialRun {
 public:
  // `context` must outlive the run.
  TrialRun(const TrialContext& context, int index);

  // Measures where the robot is now and whether the trial goes on: false once it left the corridor or ran out of
  // time (TrialResult::end says which). Call once per step, before Render().
  bool Continues();
  // The robot's camera frame at this step (frame index = step, timestamp = time()).
  Frame Render();
  double time() const { return step_ * dt_; }
  int step() const { return step_; }
  double dt() const { return dt_; }
  const Pose2d& pose() const { return robot_.pose(); }  // the truth
  const OdometrySample& odometry() const { return robot_.odometry(); }

  // What the brain made of this step's frame; `step_seconds` what it took (rendering excluded). A step in the
  // state kReachedGoal ends the trial as reaching the goal.
  void Record(const LocalizationResult& localization, const ControlStep& step, double step_seconds);
  // Drives the command for one control period: the next step.
  void Drive(const VelocityCommand& command);

  // The trial's result: its end, final error, success and samples.
  TrialResult Finish();

 private:
  const TrialContext& context_;
  TrialResult trial_;
  DifferentialDriveRobot robot_;
  double dt_ = 0.0;
  double time_limit_ = 0.0;
  double room_ = 0.0;  // how far from the corridor's centre line the robot may be
  // How far along the route one step may take the robot (twice the top speed's step, for the speed noise, and at
  // least 1 m): where it is on the route is searched within that of where it was.
  double reach_ = 0.0;
  int step_ = 0;
  double s_ = 0.0;         // arc length along the route of the nearest point
  double corridor_s_ = 0;  // and along the corridor
  double lateral_ = 0.0;   // this step's lateral error
  double step_total_ = 0.0;
  double render_total_ = 0.0;
};

}  // namespace vmap
