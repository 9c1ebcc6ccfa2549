#pragma once
// Stage 4 of García-Pintos et al. 2023, autonomous navigation: turns each frame's localization against a map
// into a velocity command for a differential-drive robot, until it reaches the route's goal key image.
//
//   TaughtRoute route = MakeTaughtRoute(map, PlanRoute(map, from, to).keys, teach_odometry);
//   LocalizerOptions localizer_options = ...; localizer_options.route = route.keys;   // the same route
//   RouteController controller(route, ControllerOptions{});
//   for each camera frame:  ControlStep step = controller.Update(t, localizer.Localize(frame, features), &odom);
//                           publish step.command (v m/s, w rad/s; REP 103: w > 0 turns left)
//
// - starting: nothing is commanded until a frame is localized (the "first localization" signal: `localized`).
//   The robot may start anywhere on the route: it follows it from where it is localized.
// - following: the forward speed is the taught one (or ControllerOptions::speed), the turn rate comes from the
//   steering law (ControlLaw) on the target key image (the localizer's next_key; the goal at the route's end).
//   Which key image is the target moves on with the localizer's progress along the route (next_key becomes
//   key where the frame matches it better).
// - turning: a heading error above turn_in_place_deg: the robot turns on the spot first.
// - lost: a frame that is lost or uncertain (anything but tracking or relocalized) is not steered by: the robot
//   slows to a stop over lost_stop_seconds with the taught turn rate, then waits; it resumes when a frame is
//   localized again.
// - search (starting or lost, steering "search"): standing search_after_seconds without a usable frame, the robot
//   sweeps its heading search_angle_deg either way until a frame localizes.
// - reached goal: at the route's end, once the goal key image's scene appears as large as in the key image
//   (ApparentLogScale within goal_scale_tolerance, and within goal_scale_share of how much it grows over the
//   last stretch where the map tells): the robot stops and stays stopped until Reset.

#include <deque>
#include <limits>
#include <optional>
#include <string>

#include "vmap/control/controller_options.h"
#include "vmap/control/route_tracking.h"
#include "vmap/control/taught_route.h"
#include "vmap/core/enum_names.h"
#include "vmap/localization/localizer.h"
#include "vmap/sources/odometry.h"

namespace vmap {

enum class ControllerState { kStarting, kFollowing, kTurning, kLost, kReachedGoal };
inline constexpr EnumName<ControllerState> kControllerStateNames[] = {{ControllerState::kStarting, "starting"},
                                                                      {ControllerState::kFollowing, "following"},
                                                                      {ControllerState::kTurning, "turning"},
                                                                      {ControllerState::kLost, "lost"},
                                                                      {ControllerState::kReachedGoal, "reached goal"}};
std::string ControllerStateName(ControllerState state);

struct VelocityCommand {
  double linear = 0.0;   // m/s along the robot's forward axis (negative: reversing)
  double angular = 0.0;  // rad/s, counter-clockwise seen from above

  bool stops() const { return linear == 0.0 && angular == 0.0; }
};

// What the controller did with one frame.
struct ControlStep {
  VelocityCommand command;
  ControllerState state = ControllerState::kStarting;
  bool localized = false;  // a frame has been localized since the start (or Reset)
  // How the turn rate was computed: "servo", "bearnav" (the heading law), "taught" (lost: the taught turn rate
  // only), "turn in place" or "none" (stopped).
  std::string steering = "none";
  int route_position = -1;  // the route position of the key image the robot is at; -1 before localization
  int target_key = -1;      // the key image steered to; -1 when none
  // The signals the law read (NaN when not used): the heading offset (rad, left positive), the servo's bearing
  // to the target and angle to its line (rad), and the goal's apparent log scale at the route's end.
  double heading_offset = std::numeric_limits<double>::quiet_NaN();
  double bearing = std::numeric_limits<double>::quiet_NaN();
  double line_angle = std::numeric_limits<double>::quiet_NaN();
  double goal_log_scale = std::numeric_limits<double>::quiet_NaN();
  // Tracker law: the estimated offset from the taught path (m, left positive) and heading error (rad), and the
  // measurements the frame gave the estimate; NaN / 0 otherwise.
  double lateral_estimate = std::numeric_limits<double>::quiet_NaN();
  double heading_error_estimate = std::numeric_limits<double>::quiet_NaN();
  double arc_estimate = std::numeric_limits<double>::quiet_NaN();  // where along the taught path (m)
  TrackingObservation observation;
  double seconds = 0.0;  // time spent in Update
};

class RouteController {
 public:
  // Throws OptionError for bad options and InputError for a route without segments or, without a camera and
  // options.focal_px, no way to turn pixel headings into angles.
  RouteController(TaughtRoute route, ControllerOptions options);

  // One control step at time `time` (seconds, increasing) with the localization of the frame taken then and,
  // when the robot has it, its odometry at that time (nullptr: vision alone). A time before the last step's (a
  // clock reset, a bag played again) is a step of no duration: the times the controller measures go on from it.
  ControlStep Update(double time, const LocalizationResult& localization, const OdometrySample* odometry = nullptr);

  // Forgets everything: the next frame starts the run again (starting state).
  void Reset();

  // The robot was told to stop outside the controller (a frame that could not be read, a camera gone quiet): the
  // next command starts from rest, as a first one does, and the time stopped is not taken as driven at the last
  // command. Where the robot is on the route stays.
  void Stopped();

  const TaughtRoute& route() const { return route_; }
  const ControllerOptions& options() const { return options_; }

 private:
  // Forward speed (m/s, signed) and taught turn rate (rad/s) on the segment at `position` (the last one
  // beyond the route's end).
  double NominalSpeed(int position) const;
  double TaughtTurnRate(int position, double speed) const;
  // How much the taught path turns between the robot and the target key image: the segment's turn times the
  // share of it still ahead (1 - progress); 0 at the goal or where the turn is unknown.
  double RemainingTurn(int position, double progress) const;
  VelocityCommand Limit(VelocityCommand wanted, double dt) const;
  // +1 where the goal's scene grows as the robot nears the goal, -1 where it shrinks: a route driven backwards
  // reverses with the camera facing as it was taught, away from the goal.
  double GoalScaleSign() const;
  // The goal's apparent log scale, times GoalScaleSign(), at and above which the goal is reached
  // (goal_scale_tolerance, goal_scale_share).
  double GoalLogScaleThreshold() const;
  // How far beyond the end of the metric path `pose` is, along its last stretch (m; negative before it).
  double PastTheEnd(const cv::Vec3d& pose) const;

  TaughtRoute route_;
  ControllerOptions options_;
  double focal_px_ = std::numeric_limits<double>::quiet_NaN();
  std::optional<double> last_time_;
  std::optional<double> last_usable_time_;
  std::optional<OdometrySample> last_odometry_;
  VelocityCommand last_command_;
  bool localized_ = false;
  bool reached_goal_ = false;
  int position_ = -1;        // route position of the key image the robot is at
  double fraction_ = 0.0;    // progress from it to the next one (the localizer's; odometry's while lost)
  double lost_speed_ = 0.0;  // the speed commanded on the last usable frame
  // The tracker law's estimate (options.law kTracker on a metric route).
  std::optional<RouteTracking> tracking_;
  // The search (ControllerOptions::search_after_seconds): since when no frame was usable, how far the heading
  // has swept from where the search began (radians, left positive), and which way it turns now.
  std::optional<double> unusable_since_;
  // The servo's filtered line angle (beta) and when it was last measured.
  std::optional<double> line_angle_;
  double line_angle_time_ = 0.0;
  double swept_ = 0.0;
  double search_direction_ = 1.0;
  // The goal key image's apparent log scale in the last (up to three) frames localized at it.
  std::deque<double> goal_log_scales_;
};

}  // namespace vmap
