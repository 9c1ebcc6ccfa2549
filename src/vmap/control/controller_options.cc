#include "vmap/control/controller_options.h"

#include <cmath>

#include <fmt/format.h>

#include "vmap/core/error.h"

namespace vmap {

ControlLaw ParseControlLaw(const std::string& name) { return ParseEnum(kControlLawNames, name, "control law"); }
std::string ControlLawName(ControlLaw law) { return EnumToName(kControlLawNames, law); }

void ControllerOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"law", "--law", "Steering law: "}.ListingNames(),
                EnumField(law, kControlLawNames, ParseControlLaw));
  visitor.Visit({"speed", "--speed", "Forward speed where the teach run's is unknown (m/s)"}, speed);
  visitor.Visit({"speed_scale", "--speed-scale", "The taught speed times this, where the teach odometry gives it"},
                speed_scale);
  visitor.Visit({"max_speed", "--max-speed", "Largest forward speed (m/s)"}, max_speed);
  visitor.Visit({"max_angular_speed", "--max-angular-speed", "Largest turn rate (rad/s)"}, max_angular_speed);
  visitor.Visit({"max_acceleration", "--max-acceleration", "Largest change of speed (m/s^2)"}, max_acceleration);
  visitor.Visit({"max_angular_acceleration", "--max-angular-acceleration", "Largest change of turn rate (rad/s^2)"},
                max_angular_acceleration);
  visitor.Visit(
      {"heading_gain", "--heading-gain", "Turn rate per radian of heading (1/s; bearnav, and servo's fallback)"},
      heading_gain);
  visitor.Visit(
      {"bearing_gain", "--bearing-gain", "Servo: turn rate per radian of bearing to the target key image (1/s)"},
      bearing_gain);
  visitor.Visit({"line_gain", "--line-gain",
                 "Servo: turn rate per radian between the bearing and the target's heading (1/s, negative)"},
                line_gain);
  visitor.Visit({"pose_agreement_deg", "--pose-agreement",
                 "Servo: a pose steers when its rotation agrees with the heading within this (degrees)"},
                pose_agreement_deg);
  visitor.Visit({"line_filter_seconds", "--line-filter",
                 "Servo: seconds over which the line angle is smoothed (0 = not smoothed)"},
                line_filter_seconds);
  visitor.Visit({"convergence_distance", "--convergence-distance",
                 "Tracker: distance along the path over which an offset decays (m)"},
                convergence_distance);
  visitor.Visit({"turn_in_place_deg", "--turn-in-place", "Heading error above which the robot turns on the spot (deg)"},
                turn_in_place_deg);
  visitor.Visit({"lost_stop_seconds", "--lost-stop", "Seconds to slow to a stop once localization is lost"},
                lost_stop_seconds);
  visitor.Visit(
      {"search_after_seconds", "--search-after",
       "Seconds standing without localization before the robot sweeps its heading to find the route (0 = never)"},
      search_after_seconds);
  visitor.Visit({"search_angle_deg", "--search-angle", "How far either way the search sweeps (degrees)"},
                search_angle_deg);
  visitor.Visit({"search_turn_rate", "--search-turn-rate", "Turn rate of the search (rad/s)"}, search_turn_rate);
  visitor.Visit({"goal_scale_tolerance", "--goal-scale-tolerance",
                 "Goal reached when the scene is at most this much smaller than in the goal key image (0.02 = 2 %)"},
                goal_scale_tolerance);
  visitor.Visit({"goal_scale_share", "--goal-scale-share",
                 "... and when at most this share of the growth of the goal's scene over the last stretch remains "
                 "(measured in the map; the stricter of the two; 0: the tolerance alone)"},
                goal_scale_share);
  visitor.Visit({"goal_speed_share", "--goal-speed-share", "Speed on the last stretch, as a share of the cruise speed"},
                goal_speed_share);
  visitor.Visit({"focal_px", "--focal-px", "Focal length in pixels for maps without a camera (0 = the map's)"},
                focal_px);
}

namespace {

void CheckRange(const char* field, double value, double low, double high, const char* unit, double fallback,
                bool low_open = false) {
  const bool ok = low_open ? (value > low && value <= high) : (value >= low && value <= high);
  if (!ok) {
    throw OptionError(field, fmt::format("{} {} is outside {}{}, {}]; the default is {}", value, unit,
                                         low_open ? "(" : "[", low, high, fallback));
  }
}

}  // namespace

void ControllerOptions::Check() const {
  const ControllerOptions d;
  CheckRange("speed", speed, 0.0, 10.0, "m/s", d.speed, true);
  CheckRange("speed_scale", speed_scale, 0.0, 10.0, "", d.speed_scale, true);
  CheckRange("max_speed", max_speed, 0.0, 10.0, "m/s", d.max_speed, true);
  CheckRange("max_angular_speed", max_angular_speed, 0.0, 20.0, "rad/s", d.max_angular_speed, true);
  CheckRange("max_acceleration", max_acceleration, 0.0, 100.0, "m/s^2", d.max_acceleration, true);
  CheckRange("max_angular_acceleration", max_angular_acceleration, 0.0, 100.0, "rad/s^2", d.max_angular_acceleration,
             true);
  CheckRange("heading_gain", heading_gain, 0.0, 100.0, "1/s", d.heading_gain, true);
  CheckRange("bearing_gain", bearing_gain, 0.0, 100.0, "1/s", d.bearing_gain);
  CheckRange("line_gain", line_gain, -100.0, 0.0, "1/s", d.line_gain);
  CheckRange("pose_agreement_deg", pose_agreement_deg, 0.0, 180.0, "deg", d.pose_agreement_deg, true);
  CheckRange("line_filter_seconds", line_filter_seconds, 0.0, 60.0, "s", d.line_filter_seconds);
  CheckRange("convergence_distance", convergence_distance, 0.05, 100.0, "m", d.convergence_distance);
  CheckRange("turn_in_place_deg", turn_in_place_deg, 0.0, 180.0, "deg", d.turn_in_place_deg, true);
  CheckRange("lost_stop_seconds", lost_stop_seconds, 0.0, 3600.0, "s", d.lost_stop_seconds);
  CheckRange("search_after_seconds", search_after_seconds, 0.0, 3600.0, "s", d.search_after_seconds);
  CheckRange("search_angle_deg", search_angle_deg, 0.0, 180.0, "deg", d.search_angle_deg, true);
  CheckRange("search_turn_rate", search_turn_rate, 0.0, 20.0, "rad/s", d.search_turn_rate, true);
  CheckRange("goal_scale_tolerance", goal_scale_tolerance, 0.0, 0.5, "", d.goal_scale_tolerance, true);
  CheckRange("goal_scale_share", goal_scale_share, 0.0, 1.0, "", d.goal_scale_share);
  CheckRange("goal_speed_share", goal_speed_share, 0.0, 1.0, "", d.goal_speed_share, true);
  CheckRange("focal_px", focal_px, 0.0, 1e6, "px", d.focal_px);
}

}  // namespace vmap
