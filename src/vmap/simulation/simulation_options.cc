#include "vmap/simulation/simulation_options.h"

#include <cmath>

#include <fmt/format.h>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void SimulationOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Simulation: the route and the trials");
  visitor.Visit({"route", "--route", "Route: straight, turn, s-curve, loop, or a CSV of x,y waypoints (m)"}, route);
  visitor.Visit(OptionField{"trials", "--trials", "Repeat runs from random offsets"}.Within(1, 100000), trials);
  visitor.Visit(OptionField{"seed", "--seed", "Seed of the offsets and the noise"}.AtLeast(0), seed);
  visitor.Visit(
      OptionField{"max_lateral_offset", "--lateral-offset", "Largest sideways start offset (m; uniform in +-)"}
          .Within(0, 50)
          .Unit("m"),
      max_lateral_offset);
  visitor.Visit(
      OptionField{"max_heading_offset_deg", "--heading-offset", "Largest start heading offset (degrees; uniform in +-)"}
          .Within(0, 90)
          .Unit("degrees"),
      max_heading_offset_deg);
  visitor.Visit(
      OptionField{"teach_speed", "--teach-speed", "Speed of the teach run (m/s)"}.Within(0.01, 10).Unit("m/s"),
      teach_speed);
  visitor.Visit(OptionField{"rate", "--rate", "Frames and control steps per second (Hz)"}.Within(1, 100).Unit("Hz"),
                rate);
  visitor.Visit(
      OptionField{"goal_tolerance", "--goal-tolerance", "A trial succeeds when it stops this near the goal (m)"}
          .Within(0.01, 100)
          .Unit("m"),
      goal_tolerance);
  visitor.Visit(
      OptionField{"time_limit_factor", "--time-limit", "A trial ends after this many teach durations, plus 20 s"}
          .Within(1, 100),
      time_limit_factor);
  visitor.Visit(
      OptionField{"robot_radius", "--robot-radius", "Robot half width: nearer a wall than this is a crash (m)"}
          .Within(0, 5)
          .Unit("m"),
      robot_radius);
  visitor.Visit({"teach_textures", "--teach-textures", "Folder of photographs on the teach world's walls and floor"},
                teach_textures);
  visitor.Visit({"repeat_textures", "--repeat-textures",
                 "Folder of the same photographs in another season, for the repeat world (default: the teach ones)"},
                repeat_textures);
  visitor.Visit(
      {"use_odometry", "!--no-odometry", "Do not give the repeat run's odometry to the controller and the localizer"},
      use_odometry);
  visitor.Visit(
      OptionField{"threads", "--threads", "Trials run at once (0 = one per core)"}.NotRecorded().Within(0, 256).Meaning(
          "0: one per core"),
      threads);
  visitor.VisitNested("corridor", corridor, Nesting{true, {}});
  visitor.VisitNested("camera", camera);
  visitor.VisitNested("noise", noise, Nesting{true, {}});
  visitor.VisitNested("controller", controller, Nesting{true, {}});
  visitor.VisitNested("localizer", localizer, Nesting{false, {"verifier", "translation", "similarity", "route"}});
}

void SimulationOptions::Check() const {
  if (route.empty()) throw OptionError("route", "is empty; give straight, turn, s-curve, loop or a CSV file");
  CheckFieldRanges(*this);
  CheckField("corridor", corridor);
  CheckField("camera", camera);
  CheckField("noise", noise);
  CheckField("controller", controller);
  CheckField("localizer", localizer);
  if (teach_textures.empty() && !repeat_textures.empty()) {
    throw OptionError("repeat_textures", "replaces the teach textures in another season; give teach_textures too",
                      {"teach_textures"});
  }
  if (!(camera.mount_height < corridor.wall_height)) {
    throw OptionError("camera.mount_height",
                      fmt::format("{} m puts the camera above the {} m walls; lower it or raise --wall-height",
                                  camera.mount_height, corridor.wall_height));
  }
  // The robot must fit the corridor, and a start offset must leave it inside.
  const double room = 0.5 * corridor.width - robot_radius;
  if (!(room > 0.0)) {
    throw OptionError("robot_radius",
                      fmt::format("{} m makes the robot {} m wide, no narrower than the {} m corridor; give a smaller "
                                  "radius or a wider --corridor-width",
                                  robot_radius, 2 * robot_radius, corridor.width));
  }
  if (!(max_lateral_offset < room)) {
    throw OptionError("max_lateral_offset",
                      fmt::format("{} m does not fit the corridor: a robot {} m wide starts at most {:.2f} m off the "
                                  "centre of a {} m corridor; give a smaller offset or a wider --corridor-width",
                                  max_lateral_offset, 2 * robot_radius, room, corridor.width));
  }
}

}  // namespace vmap
