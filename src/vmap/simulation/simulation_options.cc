#include "vmap/simulation/simulation_options.h"

#include <cmath>

#include <fmt/format.h>

#include "vmap/core/error.h"

namespace vmap {

void SimulationOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"route", "--route", "Route: straight, turn, s-curve, loop, or a CSV of x,y waypoints (m)"}, route);
  visitor.Visit({"trials", "--trials", "Repeat runs from random offsets"}, trials);
  visitor.Visit({"seed", "--seed", "Seed of the offsets and the noise"}, seed);
  visitor.Visit({"max_lateral_offset", "--lateral-offset", "Largest sideways start offset (m; uniform in +-)"},
                max_lateral_offset);
  visitor.Visit({"max_heading_offset_deg", "--heading-offset", "Largest start heading offset (degrees; uniform in +-)"},
                max_heading_offset_deg);
  visitor.Visit({"teach_speed", "--teach-speed", "Speed of the teach run (m/s)"}, teach_speed);
  visitor.Visit({"rate", "--rate", "Frames and control steps per second (Hz)"}, rate);
  visitor.Visit({"goal_tolerance", "--goal-tolerance", "A trial succeeds when it stops this near the goal (m)"},
                goal_tolerance);
  visitor.Visit({"time_limit_factor", "--time-limit", "A trial ends after this many teach durations, plus 20 s"},
                time_limit_factor);
  visitor.Visit({"robot_radius", "--robot-radius", "Robot half width: nearer a wall than this is a crash (m)"},
                robot_radius);
  visitor.Visit({"teach_textures", "--teach-textures", "Folder of photographs on the teach world's walls and floor"},
                teach_textures);
  visitor.Visit({"repeat_textures", "--repeat-textures",
                 "Folder of the same photographs in another season, for the repeat world (default: the teach ones)"},
                repeat_textures);
  visitor.Visit({"use_odometry", "!--no-odometry", "Do not give the repeat run's odometry to the controller"},
                use_odometry);
  visitor.Visit(OptionField{"threads", "--threads", "Trials run at once (0 = one per core)"}.NotRecorded(), threads);
  visitor.VisitNested("corridor", corridor, Nesting{true, {}});
  visitor.VisitNested("camera", camera);
  visitor.VisitNested("noise", noise, Nesting{true, {}});
  visitor.VisitNested("controller", controller, Nesting{true, {}});
  visitor.VisitNested("localizer", localizer, Nesting{false, {"verifier", "translation", "similarity", "route"}});
}

void SimulationOptions::Check() const {
  if (route.empty()) throw OptionError("route", "is empty; give straight, turn, s-curve, loop or a CSV file");
  if (trials < 1 || trials > 100000)
    throw OptionError("trials", fmt::format("{} is outside [1, 100000]; the default is 10", trials));
  auto check = [](const char* field, double value, double low, double high, const char* unit, double fallback) {
    if (!(value >= low && value <= high)) {
      throw OptionError(field,
                        fmt::format("{} {} is outside [{}, {}]; the default is {}", value, unit, low, high, fallback));
    }
  };
  check("max_lateral_offset", max_lateral_offset, 0.0, 50.0, "m", 0.5);
  check("max_heading_offset_deg", max_heading_offset_deg, 0.0, 90.0, "degrees", 10.0);
  check("teach_speed", teach_speed, 0.01, 10.0, "m/s", 0.3);
  check("rate", rate, 1.0, 100.0, "Hz", 10.0);
  check("goal_tolerance", goal_tolerance, 0.01, 100.0, "m", 0.3);
  check("time_limit_factor", time_limit_factor, 1.0, 100.0, "", 3.0);
  check("robot_radius", robot_radius, 0.0, 5.0, "m", 0.15);
  if (seed < 0) throw OptionError("seed", fmt::format("{} is negative; give 0 or more (the default is 1)", seed));
  if (threads < 0 || threads > 256)
    throw OptionError("threads", fmt::format("{} is outside [0, 256] (0 = one per core)", threads));
  CheckField("corridor", corridor);
  CheckField("camera", camera);
  CheckField("noise", noise);
  CheckField("controller", controller);
  CheckField("localizer", localizer);
  if (!(camera.mount_height < corridor.wall_height)) {
    throw OptionError("camera.mount_height",
                      fmt::format("{} m puts the camera above the {} m walls; lower it or raise --wall-height",
                                  camera.mount_height, corridor.wall_height));
  }
  // A start offset must leave the robot inside the corridor.
  const double room = 0.5 * corridor.width - robot_radius;
  if (!(max_lateral_offset < room)) {
    throw OptionError("max_lateral_offset",
                      fmt::format("{} m does not fit the corridor: a robot {} m wide starts at most {:.2f} m off the "
                                  "centre of a {} m corridor; give a smaller offset or a wider --corridor-width",
                                  max_lateral_offset, 2 * robot_radius, room, corridor.width));
  }
}

}  // namespace vmap
