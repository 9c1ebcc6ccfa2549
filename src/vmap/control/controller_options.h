#pragma once
// The options of a route controller (route_controller.h): its steering law, speeds, gains and limits, each with
// its unit and its default (measured in the closed-loop simulator: docs/drive.md).

#include <string>

#include "vmap/core/enum_names.h"
#include "vmap/core/option_fields.h"

namespace vmap {

// How the turn rate is computed from a frame's localization (docs/drive.md, "Control laws").
// kBearnav: the taught turn rate plus a gain times the heading against the target key image (Krajnik et al.'s
//   Bearnav: image displacement corrects the heading, the taught profile does the rest).
// kServo: a visual servo to the target key image where its relative pose has a translation to trust: the
//   bearing to the key image's position and the angle of that bearing to the key image's own heading, steered
//   to zero like a unicycle parking on a line (polar coordinates, scale-free); the Bearnav law where the
//   translation is unknown.
// kTracker: where the teach run had odometry (TaughtRoute::metric()), the robot's pose on the taught path is
//   estimated from every frame's headings and bearings to the key images, whose poses the teach odometry gives
//   (route_pose_estimator.h), and a path-following law steers it onto the taught path (path_tracker.h); the
//   servo law where the route is not metric. The default: a measurement far from what the estimate predicts is
//   refused, where the servo law steers by every pose it is given (docs/drive.md has the figures).
enum class ControlLaw { kBearnav, kServo, kTracker };
inline constexpr EnumName<ControlLaw> kControlLawNames[] = {
    {ControlLaw::kBearnav, "bearnav"}, {ControlLaw::kServo, "servo"}, {ControlLaw::kTracker, "tracker"}};
ControlLaw ParseControlLaw(const std::string& name);
std::string ControlLawName(ControlLaw law);

struct ControllerOptions {
  ControlLaw law = ControlLaw::kTracker;
  // Forward speed (m/s) where the teach run's speed is unknown (no teach odometry); with it, the taught speed of
  // each stretch times `speed_scale`.
  double speed = 0.3;
  double speed_scale = 1.0;
  double max_speed = 1.0;                 // m/s
  double max_angular_speed = 1.0;         // rad/s
  double max_acceleration = 0.5;          // m/s^2, speeding up and slowing down
  double max_angular_acceleration = 3.0;  // rad/s^2
  // Bearnav law, and the servo's fallback: turn rate per radian of heading (1/s).
  double heading_gain = 1.0;
  // Servo law: turn rate per radian of bearing to the target key image (k_alpha) and per radian of angle
  // between that bearing and the key image's heading (k_beta, negative: it turns the robot onto the taught
  // line before it gets there). Stable for k_alpha > 0 > k_beta.
  double bearing_gain = 1.5;
  double line_gain = -0.6;
  // Servo: a pose steers only when its rotation agrees with the features' heading within this (degrees), and its
  // line angle is smoothed over this many seconds (first-order filter; 0: each frame's as it is).
  double pose_agreement_deg = 5.0;
  double line_filter_seconds = 0.5;
  // Tracker law: the distance along the path over which a lateral offset and a heading error decay (m).
  double convergence_distance = 0.6;
  // A heading error above this turns the robot on the spot before it drives (degrees): a repeat started
  // facing away from the route does not drive off it.
  double turn_in_place_deg = 35.0;
  // After the last usable frame the robot slows down to a stop over this many seconds (following the taught
  // turn rate) and waits, turning nowhere, until it is localized again.
  double lost_stop_seconds = 1.0;
  // Standing without a usable frame (not yet localized at the start, or stopped after losing it) for this many
  // seconds, the robot sweeps its heading search_angle_deg either way of where it stood, at search_turn_rate,
  // until a frame localizes: a robot put down facing a wall, or pushed off the route, finds it again. 0: never.
  double search_after_seconds = 2.0;
  double search_angle_deg = 30.0;
  double search_turn_rate = 0.3;  // rad/s
  // The goal is reached when the frame shows the goal key image's scene at least this close to the size it has
  // in the goal key image (relative: 0.02 = 2 % smaller), or larger (passed).
  double goal_scale_tolerance = 0.02;
  // ... and, where the map tells how much the goal's scene grows over the route's last stretch (its link's
  // apparent scale change, TaughtSegment::log_scale), when at most this share of that growth remains: the
  // stricter of the two. 2 % is metres short of the goal where the scene is deep (a long corridor ahead grows
  // little as the robot approaches); a share of the last stretch's growth is a share of its length whatever the
  // depth. 0: the tolerance alone.
  double goal_scale_share = 0.1;
  // Speed on the last stretch, as a share of the cruise speed: a smaller overshoot when the goal is seen late.
  double goal_speed_share = 0.5;
  // Converts pixel headings to angles when the map has no camera (its focal length in pixels); 0: the map's
  // camera (an error without one).
  double focal_px = 0.0;

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

}  // namespace vmap
