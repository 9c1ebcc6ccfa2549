#pragma once
// One repeat run of a closed-loop simulation: the robot starts near the route's start with an offset, and each
// control step renders its camera's frame, localizes it against the map, asks the controller for a command and
// drives it, until the controller stops at the goal, the robot leaves the corridor, or time runs out.

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "vmap/control/route_controller.h"
#include "vmap/control/taught_route.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localizer.h"
#include "vmap/simulation/corridor_world.h"
#include "vmap/simulation/route_path.h"
#include "vmap/simulation/simulation_options.h"

namespace vmap {

struct TrialSample {
  double time = 0.0;
  Pose2d pose;           // the truth
  double s = 0.0;        // arc length along the route of the nearest point
  double lateral = 0.0;  // signed distance to the route, left positive (m)
  LocalizationStatus status = LocalizationStatus::kLost;
  int key = -1;
  ControllerState state = ControllerState::kStarting;
  std::string steering;
  double heading_offset = 0.0;  // what the controller read (ControlStep; NaN when not used)
  double bearing = 0.0;
  double line_angle = 0.0;
  double lateral_estimate = 0.0;        // the tracker's (ControlStep; NaN otherwise)
  double heading_error_estimate = 0.0;  // the tracker's (rad, ControlStep; NaN otherwise)
  double arc_estimate = 0.0;            // the tracker's (m along the taught path; NaN otherwise)
  TrackingObservation observation;      // what the frame gave the tracker's estimate
  double translation_sigma_deg = 0.0;   // of the target's pose (KeyComparison; NaN without one)
  // The bearing to the target key image from the frame's relative pose where its translation is known (rad, the
  // tracker's measurement, whatever the law; NaN otherwise): against true_bearing, how wrong the measurement is.
  double pose_bearing = std::numeric_limits<double>::quiet_NaN();
  // The robot's heading against the target key image's from the relative pose's rotation (rad, left positive; NaN
  // without a pose): the tracker's heading measurement.
  double pose_heading = std::numeric_limits<double>::quiet_NaN();
  int target_verified = 0;  // verified matches with the target key image
  // How large key's scene appears in the frame against the key image (ApparentLogScale; NaN where unknown).
  double key_log_scale = std::numeric_limits<double>::quiet_NaN();
  // The truth of the same, from the target key image's pose in the teach run (NaN without a target).
  double true_bearing = std::numeric_limits<double>::quiet_NaN();
  double true_line_angle = std::numeric_limits<double>::quiet_NaN();
  VelocityCommand command;
  double step_seconds = 0.0;  // features, localization and control (rendering excluded)
};

struct TrialResult {
  int index = 0;
  double start_lateral = 0.0;      // m
  double start_heading_deg = 0.0;  // left positive
  bool reached_goal = false;       // the controller stopped, saying it reached the goal
  bool success = false;            // ... within goal_tolerance of the goal key image
  std::string end;                 // "reached goal", "left the corridor" or "time limit"
  double final_error = 0.0;        // metres from the goal key image's position when the trial ended
  double lateral_rms_second_half = std::numeric_limits<double>::quiet_NaN();  // over samples past half the route
  double lateral_max_second_half = std::numeric_limits<double>::quiet_NaN();
  double lateral_max = 0.0;
  // Where the lateral error came within 0.1 m to stay (arc length, m); NaN when it never did.
  double settled_at = std::numeric_limits<double>::quiet_NaN();
  int frames = 0;
  int frames_lost = 0;  // not steered by: lost or uncertain
  double mean_step_seconds = 0.0;
  double max_step_seconds = 0.0;
  double mean_render_seconds = 0.0;
  double duration = 0.0;  // simulated seconds
  // One per frame, and the pose that ended the trial when no frame was taken there (its last frame's fields, with
  // the pose, time, s and lateral of the end).
  std::vector<TrialSample> samples;
};

// What every trial of a simulation shares.
struct TrialContext {
  const SimulatedRoute* route = nullptr;
  const CorridorWorld* world = nullptr;  // the repeat world
  const LocalizationMap* map = nullptr;
  LocalizerOptions localizer;  // following the map, along taught.keys
  TaughtRoute taught;
  std::vector<OdometrySample> teach_odometry;  // the teach run's: with the repeat's, the localizer's pace
  std::vector<Pose2d> key_image_poses;         // where the teach run took each key image
  double teach_duration = 0.0;                 // seconds
  SimulationOptions options;
  std::function<void()> after_frame;  // optional, after each rendered frame; may throw to stop the trial
};

// Trial `index` (its offsets and noise drawn from options.seed and the index).
TrialResult RunTrial(const TrialContext& context, int index);

}  // namespace vmap
