#include "vmap/control/controller_options.h"

#include <fmt/format.h>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

ControlLaw ParseControlLaw(const std::string& name) { return ParseEnum(kControlLawNames, name, "control law"); }
std::string ControlLawName(ControlLaw law) { return EnumToName(kControlLawNames, law); }

void ControllerOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Controller: velocity commands from localization");
  visitor.Visit(OptionField{"law", "--law", "Steering law: "}.ListingNames(),
                EnumField(law, kControlLawNames, ParseControlLaw));
  visitor.Visit(OptionField{"speed", "--speed", "Forward speed where the teach run's is unknown (m/s)"}
                    .Within(0, 10)
                    .ExcludingMin()
                    .Unit("m/s"),
                speed);
  visitor.Visit(
      OptionField{"speed_scale", "--speed-scale", "The taught speed times this, where the teach odometry gives it"}
          .Within(0, 10)
          .ExcludingMin(),
      speed_scale);
  visitor.Visit(
      OptionField{"max_speed", "--max-speed", "Largest forward speed (m/s)"}.Within(0, 10).ExcludingMin().Unit("m/s"),
      max_speed);
  visitor.Visit(OptionField{"max_angular_speed", "--max-angular-speed", "Largest turn rate (rad/s)"}
                    .Within(0, 20)
                    .ExcludingMin()
                    .Unit("rad/s"),
                max_angular_speed);
  visitor.Visit(OptionField{"max_acceleration", "--max-acceleration", "Largest change of speed (m/s^2)"}
                    .Within(0, 100)
                    .ExcludingMin()
                    .Unit("m/s^2"),
                max_acceleration);
  visitor.Visit(
      OptionField{"max_angular_acceleration", "--max-angular-acceleration", "Largest change of turn rate (rad/s^2)"}
          .Within(0, 100)
          .ExcludingMin()
          .Unit("rad/s^2"),
      max_angular_acceleration);
  visitor.Visit(OptionField{"heading_gain", "--heading-gain",
                            "Turn rate per radian of heading (1/s; bearnav, and servo's fallback)"}
                    .Within(0, 100)
                    .ExcludingMin()
                    .Unit("1/s"),
                heading_gain);
  visitor.Visit(OptionField{"bearing_gain", "--bearing-gain",
                            "Servo: turn rate per radian of bearing to the target key image (1/s)"}
                    .Within(0, 100)
                    .ExcludingMin()  // k_b > 0 > k_l: the unicycle law's stability condition (docs/drive.md)
                    .Unit("1/s"),
                bearing_gain);
  visitor.Visit(OptionField{"line_gain", "--line-gain",
                            "Servo: turn rate per radian between the bearing and the target's heading (1/s, negative)"}
                    .Within(-100, 0)
                    .ExcludingMax()
                    .Unit("1/s"),
                line_gain);
  visitor.Visit(OptionField{"pose_agreement_deg", "--pose-agreement",
                            "Servo: a pose steers when its rotation agrees with the heading within this (degrees)"}
                    .Within(0, 180)
                    .ExcludingMin()
                    .Unit("deg"),
                pose_agreement_deg);
  visitor.Visit(OptionField{"line_filter_seconds", "--line-filter",
                            "Servo: seconds over which the line angle is smoothed (0 = not smoothed)"}
                    .Within(0, 60)
                    .Unit("s")
                    .Meaning("0: not smoothed"),
                line_filter_seconds);
  visitor.Visit(OptionField{"convergence_distance", "--convergence-distance",
                            "Tracker: distance along the path over which an offset decays (m)"}
                    .Within(0.05, 100)
                    .Unit("m"),
                convergence_distance);
  visitor.Visit(
      OptionField{"turn_in_place_deg", "--turn-in-place", "Heading error above which the robot turns on the spot (deg)"}
          .Within(0, 180)
          .ExcludingMin()
          .Unit("deg"),
      turn_in_place_deg);
  visitor.Visit(OptionField{"lost_stop_seconds", "--lost-stop", "Seconds to slow to a stop once localization is lost"}
                    .Within(0, 3600)
                    .Unit("s"),
                lost_stop_seconds);
  visitor.Visit(
      OptionField{
          "search_after_seconds", "--search-after",
          "Seconds standing without localization before the robot sweeps its heading to find the route (0 = never)"}
          .Within(0, 3600)
          .Unit("s")
          .Meaning("0: never"),
      search_after_seconds);
  visitor.Visit(OptionField{"search_angle_deg", "--search-angle", "How far either way the search sweeps (degrees)"}
                    .Within(0, 180)
                    .ExcludingMin()
                    .Unit("deg"),
                search_angle_deg);
  visitor.Visit(OptionField{"search_turn_rate", "--search-turn-rate", "Turn rate of the search (rad/s)"}
                    .Within(0, 20)
                    .ExcludingMin()
                    .Unit("rad/s"),
                search_turn_rate);
  visitor.Visit(
      OptionField{"goal_scale_tolerance", "--goal-scale-tolerance",
                  "Goal reached when the scene is at most this much smaller than in the goal key image (0.02 = 2 %)"}
          .Within(0, 0.5)
          .ExcludingMin(),
      goal_scale_tolerance);
  visitor.Visit(
      OptionField{"goal_scale_share", "--goal-scale-share",
                  "... and when at most this share of the growth of the goal's scene over the last stretch remains "
                  "(measured in the map; the stricter of the two; 0: the tolerance alone)"}
          .Within(0, 1)
          .Meaning("0: the tolerance alone"),
      goal_scale_share);
  visitor.Visit(
      OptionField{"goal_speed_share", "--goal-speed-share", "Speed on the last stretch, as a share of the cruise speed"}
          .Within(0, 1)
          .ExcludingMin(),
      goal_speed_share);
  visitor.Visit(
      OptionField{"focal_px", "--focal-px", "Focal length in pixels for maps without a camera (0 = the map's)"}
          .Within(0, 1e6)
          .Unit("px")
          .Meaning("0: the map's"),
      focal_px);
}

void ControllerOptions::Check() const {
  CheckFieldRanges(*this);
  // The command never exceeds max_speed: a speed above it would be taken as max_speed, silently.
  if (speed > max_speed) {
    throw OptionError("speed",
                      fmt::format("{} m/s is above max_speed {} m/s; lower it, or raise max_speed", speed, max_speed),
                      {"max_speed"});
  }
}

}  // namespace vmap
