#pragma once
// The options of a closed-loop simulation (closed_loop.h, `vmap simulate`): the route and its world, the robot,
// its camera and noise, the trials and the controller under test.

#include <string>

#include "vmap/control/controller_options.h"
#include "vmap/core/option_fields.h"
#include "vmap/localization/localizer.h"
#include "vmap/simulation/corridor_world.h"
#include "vmap/simulation/robot.h"

namespace vmap {

struct SimulationOptions {
  // "straight", "turn", "s-curve", "loop" (route_path.h), or a CSV of x,y waypoints.
  std::string route = "straight";
  int trials = 10;
  int seed = 1;  // every trial's offsets and noise follow from it: the same options give the same runs
  // Each trial starts at the route's start, offset sideways uniformly in [-max, max] metres and turned uniformly
  // in [-max, max] degrees.
  double max_lateral_offset = 0.5;
  double max_heading_offset_deg = 10.0;
  double teach_speed = 0.3;  // m/s along the route
  double rate = 10.0;        // Hz: frames and control steps per second
  // A trial succeeds when the controller stops at the goal within this many metres of the goal key image.
  double goal_tolerance = 0.3;
  // A trial ends unfinished after this many times the teach run's duration, plus 20 s.
  double time_limit_factor = 3.0;
  // Robot half width: a trial whose robot comes closer than this to a wall has left the corridor.
  double robot_radius = 0.15;
  // Folders of photographs for the teach and repeat worlds (corridor_world.h); "" = procedural textures. Repeat
  // textures default to the teach ones (the same appearance).
  std::string teach_textures;
  std::string repeat_textures;
  // The repeat run's odometry goes to the controller (the teach run's gives the taught profile either way).
  bool use_odometry = true;
  int threads = 0;  // trials run at once; 0 = one per core
  CorridorOptions corridor;
  CameraRigOptions camera;
  RobotNoiseOptions noise;
  ControllerOptions controller;
  // The localizer's (its verifier, translation thresholds and similarity follow the map, as in `vmap localize`).
  LocalizerOptions localizer;

  void VisitFields(OptionFieldVisitor& visitor);
  // Throws OptionError naming the bad field, including offsets that do not fit the corridor.
  void Check() const;
};

}  // namespace vmap
