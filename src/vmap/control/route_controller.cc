#include "vmap/control/route_controller.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include <spdlog/spdlog.h>

#include "vmap/control/guidance_signals.h"
#include "vmap/core/error.h"
#include "vmap/core/numeric.h"
#include "vmap/core/stopwatch.h"

namespace vmap {

std::string ControllerStateName(ControllerState state) { return EnumToName(kControllerStateNames, state); }

RouteController::RouteController(TaughtRoute route, ControllerOptions options)
    : route_(std::move(route)), options_(options) {
  options_.Check();
  if (route_.keys.size() < 2) {
    throw InputError(route_.keys.empty()
                         ? std::string("a route to follow needs at least two key images, and this one has none")
                         : "a route to follow needs at least two key images, and this one is key image " +
                               std::to_string(route_.keys.front()) +
                               " alone: give a goal other than its start (--to and --from; a repeat run's goal and "
                               "start)");
  }
  if (route_.segments.size() + 1 != route_.keys.size()) {
    throw std::invalid_argument("RouteController: a TaughtRoute has a segment between each two of its key images");
  }
  focal_px_ = options_.focal_px > 0.0 ? options_.focal_px : route_.focal_px;
  if (options_.law == ControlLaw::kTracker && route_.metric()) tracking_.emplace(route_);
  if (!(focal_px_ > 0.0)) {
    throw OptionError("focal_px",
                      "must be given (the focal length in pixels) for a map without a camera: headings in pixels "
                      "need it to become angles");
  }
}

void RouteController::Reset() {
  last_time_.reset();
  last_usable_time_.reset();
  last_odometry_.reset();
  last_command_ = {};
  localized_ = false;
  reached_goal_ = false;
  position_ = -1;
  fraction_ = 0.0;
  lost_speed_ = 0.0;
  unusable_since_.reset();
  line_angle_.reset();
  goal_log_scales_.clear();
  if (tracking_) tracking_->Reset();
  swept_ = 0.0;
  search_direction_ = 1.0;
}

void RouteController::Stopped() {
  last_time_.reset();  // the next step is a first one: from rest, with no time driven at the last command
  last_command_ = {};
  lost_speed_ = 0.0;
}

double RouteController::NominalSpeed(int position) const {
  const int last = static_cast<int>(route_.segments.size()) - 1;
  const TaughtSegment& segment = route_.segments[std::clamp(position, 0, last)];
  double speed = segment.speed();
  speed = std::isfinite(speed) && speed > 0.0 ? speed * options_.speed_scale : options_.speed;
  // The last stretch is driven slower: the goal is seen late, and stopping takes time.
  if (position >= last) speed *= options_.goal_speed_share;
  speed = std::min(speed, options_.max_speed);
  return segment.backwards ? -speed : speed;
}

double RouteController::TaughtTurnRate(int position, double speed) const {
  const int last = static_cast<int>(route_.segments.size()) - 1;
  const TaughtSegment& segment = route_.segments[std::clamp(position, 0, last)];
  if (!std::isfinite(segment.yaw_change)) return 0.0;
  // Curvature times speed where the length is known; otherwise the taught rate, at the pace of `speed`
  // against options.speed (the teach run is taken to have been driven at it).
  if (std::isfinite(segment.length) && segment.length > 1e-3)
    return segment.yaw_change / segment.length * std::abs(speed);
  if (std::isfinite(segment.duration) && segment.duration > 1e-3) {
    return segment.yaw_change / segment.duration * std::abs(speed) / options_.speed;
  }
  return 0.0;
}

double RouteController::PastTheEnd(const cv::Vec3d& pose) const {
  const std::vector<OdometrySample>& path = route_.path;
  const cv::Point2d end(path.back().x, path.back().y);
  // The direction the teach run arrived in, from a sample a little before the end: a robot taught by hand stood at
  // the goal for the last samples, which give none.
  constexpr double kBaseline = 0.05;  // m
  for (auto sample = path.rbegin() + 1; sample != path.rend(); ++sample) {
    const cv::Point2d direction = end - cv::Point2d(sample->x, sample->y);
    const double length = cv::norm(direction);
    if (length >= kBaseline) return (cv::Point2d(pose[0], pose[1]) - end).dot(direction / length);
  }
  return 0.0;
}

double RouteController::RemainingTurn(int position, double progress) const {
  const int last = static_cast<int>(route_.segments.size()) - 1;
  if (position > last) return 0.0;  // at the goal: the target is where the robot is headed
  const double turn = route_.segments[position].yaw_change;
  if (!std::isfinite(turn)) return 0.0;
  return turn * (1.0 - (std::isfinite(progress) ? std::clamp(progress, 0.0, 1.0) : 0.0));
}

double RouteController::GoalScaleSign() const { return route_.segments.back().backwards ? -1.0 : 1.0; }

double RouteController::GoalLogScaleThreshold() const {
  const double tolerance = std::log1p(-options_.goal_scale_tolerance);
  // The last stretch's growth, where the map measured it: a share of it is a share of the stretch's length.
  const double growth = GoalScaleSign() * route_.segments.back().log_scale;
  if (!(growth < 0.0) || options_.goal_scale_share <= 0.0) return tolerance;
  return std::max(tolerance, options_.goal_scale_share * growth);
}

VelocityCommand RouteController::Limit(VelocityCommand wanted, double dt) const {
  // std::clamp passes a NaN through: a command that is no number is no motion.
  if (!std::isfinite(wanted.linear)) wanted.linear = 0.0;
  if (!std::isfinite(wanted.angular)) wanted.angular = 0.0;
  wanted.linear = std::clamp(wanted.linear, -options_.max_speed, options_.max_speed);
  wanted.angular = std::clamp(wanted.angular, -options_.max_angular_speed, options_.max_angular_speed);
  // From the last command by at most what the accelerations allow in the time since it: none at the first step (the
  // robot starts from rest) nor at a stamp that did not advance, where the first command was 20 times the limit.
  const double dv = options_.max_acceleration * dt, dw = options_.max_angular_acceleration * dt;
  wanted.linear = std::clamp(wanted.linear, last_command_.linear - dv, last_command_.linear + dv);
  wanted.angular = std::clamp(wanted.angular, last_command_.angular - dw, last_command_.angular + dw);
  return wanted;
}

ControlStep RouteController::Update(double time, const LocalizationResult& localization,
                                    const OdometrySample* odometry) {
  const auto start = std::chrono::steady_clock::now();
  if (!std::isfinite(time)) throw std::invalid_argument("RouteController::Update: the time must be a finite number");
  // An odometry sample that is no pose (a NaN from a driver) is none: it would turn every later command into NaN.
  if (odometry != nullptr &&
      !(std::isfinite(odometry->x) && std::isfinite(odometry->y) && std::isfinite(odometry->yaw))) {
    odometry = nullptr;
  }
  ControlStep step;
  if (last_time_ && time < *last_time_) {
    // A clock that went back: the stamps kept move back with it, so the time lost or searching so far still counts.
    // Kept as they were, a robot lost before a reset of 100 s drove blind at its speed for those 100 s.
    const double back = time - *last_time_;
    for (std::optional<double>* stamp : {&last_time_, &last_usable_time_, &unusable_since_}) {
      if (*stamp) **stamp += back;
    }
    line_angle_time_ += back;
  }
  const double dt = last_time_ ? time - *last_time_ : 0.0;
  last_time_ = time;
  // Metres driven (signed: negative when reversing) and radians turned since the last step: by odometry, or by the
  // last command where there is none (0 at the first step).
  double driven = last_command_.linear * dt;
  double turned = last_command_.angular * dt;
  if (odometry != nullptr) {
    if (last_odometry_) {
      const double dx = odometry->x - last_odometry_->x, dy = odometry->y - last_odometry_->y;
      const double middle = last_odometry_->yaw + 0.5 * WrapAngle(odometry->yaw - last_odometry_->yaw);
      driven = dx * std::cos(middle) + dy * std::sin(middle);
      turned = WrapAngle(odometry->yaw - last_odometry_->yaw);
      // A step no robot held to these speeds drives in the time (an odometry reset, a glitch of 1e300 m) is no
      // motion: it would move the tracker's estimate past the goal, or overflow it into NaN for the rest of the run.
      const double slack = 3.0 * std::max(dt, 0.1);
      if (std::hypot(dx, dy) > 0.2 + options_.max_speed * slack ||
          std::abs(turned) > 0.2 + options_.max_angular_speed * slack) {
        spdlog::warn(
            "the odometry jumped by {:.3g} m and {:.3g} rad in {:.3g} s, more than the robot can drive: the "
            "step is not taken as motion",
            std::hypot(dx, dy), turned, dt);
        driven = turned = 0.0;
      }
    }
    last_odometry_ = *odometry;
  } else {
    // The commands count the frames without odometry (a driver's dropout): the next sample begins a count of its
    // own, or the odometry's step over the gap would count the gap's motion a second time.
    last_odometry_.reset();
  }
  if (tracking_) tracking_->Predict(driven, turned);
  // Only frames verified at a key image of this route are steered by: a lost or uncertain frame's key images are
  // a guess (LocalizationGuidance), and so is a heading without them.
  const bool located = IsPlaced(localization.status);
  const int position = located ? route_.PositionOf(localization.key) : -1;
  const double heading_offset = HeadingOffset(localization, focal_px_);
  const bool usable = position >= 0 && std::isfinite(heading_offset);
  auto finish = [&](VelocityCommand wanted, ControllerState state) {
    // At the goal the robot stops, as fast as the decelerations allow: a stop in one step would put it short of
    // where a real base stops (0.36 m at 0.6 m/s and 0.5 m/s^2, beyond the simulator's 0.3 m tolerance).
    step.command = Limit(state == ControllerState::kReachedGoal ? VelocityCommand{} : wanted, dt);
    // What a lost robot slows down from: the speed it was given, not the speed it should have had (a robot turning
    // on the spot drove forward when it lost the route).
    if (usable) lost_speed_ = step.command.linear;
    step.state = state;
    step.localized = localized_;
    step.route_position = position_;
    last_command_ = step.command;
    step.seconds = SecondsSince(start);
    return step;
  };
  if (reached_goal_) return finish({}, ControllerState::kReachedGoal);

  const int last = static_cast<int>(route_.keys.size()) - 1;

  // The search for the route: after standing search_after_seconds without a usable frame, sweep the heading.
  auto search = [&](VelocityCommand wanted) {
    if (usable) {
      unusable_since_.reset();
      return wanted;
    }
    if (!unusable_since_) unusable_since_ = time;
    if (wanted.linear != 0.0 || options_.search_after_seconds <= 0.0 ||
        time - *unusable_since_ < options_.search_after_seconds) {
      swept_ = 0.0;
      search_direction_ = 1.0;
      return wanted;
    }
    swept_ += turned;
    if (search_direction_ * swept_ >= options_.search_angle_deg * M_PI / 180.0) search_direction_ = -search_direction_;
    step.steering = "search";
    return VelocityCommand{0.0, search_direction_ * options_.search_turn_rate};
  };
  if (usable) {
    localized_ = true;
    position_ = position;
    fraction_ = std::isfinite(localization.progress) ? localization.progress : 0.0;
    last_usable_time_ = time;
    step.target_key = localization.next_key >= 0 ? localization.next_key : localization.key;
    if (tracking_) {
      step.observation = tracking_->Observe(localization, focal_px_);
    }
    // The goal's scene against the goal key image: at the goal key image (to_key), or one stretch before it
    // against the goal as the next key image (to_next, verified on enough matches): across seasons the localizer
    // placed nearly every frame of the last stretch at the key image before the goal, and the robot drove 0.3-0.5 m
    // past the goal until the tracker's estimate stopped it (docs/drive.md).
    // As many as the localizer's counts rule asks of a key image it accepts (its default: the controller follows
    // any localizer, not only one made with the user's flags).
    const int goal_min_verified = LocalizerOptions().min_verified;
    const KeyComparison* goal = nullptr;
    if (position == last && localization.to_key.accepted) {
      goal = &localization.to_key;
    } else if (position == last - 1 && localization.next_key == route_.keys[last] && localization.to_next.matched &&
               localization.to_next.num_verified >= goal_min_verified) {
      goal = &localization.to_next;
    }
    // Reported at the goal key image even when not accepted (the --json samples show it).
    const KeyComparison* scaled = position == last ? &localization.to_key : goal;
    step.goal_log_scale = ApparentLogScale(scaled != nullptr ? scaled->verified : std::vector<Correspondence>{});
    // The median of the goal's last three scales: one frame's stray scale does not stop the robot (on the loop
    // a frame 0.36 m short measured -0.001 between two of -0.02).
    constexpr size_t kGoalFrames = 3;
    if (goal != nullptr && std::isfinite(step.goal_log_scale)) {
      goal_log_scales_.push_back(step.goal_log_scale);
      if (goal_log_scales_.size() > kGoalFrames) goal_log_scales_.pop_front();
      if (goal_log_scales_.size() == kGoalFrames &&
          GoalScaleSign() * Median(std::vector<double>(goal_log_scales_.begin(), goal_log_scales_.end())) >=
              GoalLogScaleThreshold()) {
        reached_goal_ = true;
        step.steering = "none";
        return finish({}, ControllerState::kReachedGoal);
      }
    }
  }
  if (!localized_) return finish(search({}), ControllerState::kStarting);

  if (!usable) {
    // Slow to a stop along the taught turn rate; then wait for a frame to steer by. Odometry (or the commands
    // driven) tells when the robot has driven into the next stretch, whose taught turn rate then applies.
    const double length = route_.segments[std::min(position_, last - 1)].length;
    if (driven != 0.0 && std::isfinite(length) && length > 0.0) {
      fraction_ += std::abs(driven) / length;
      while (fraction_ >= 1.0 && position_ < last) {
        fraction_ -= 1.0;
        ++position_;
      }
    }
    const double elapsed = last_usable_time_ ? time - *last_usable_time_ : options_.lost_stop_seconds;
    const double share =
        options_.lost_stop_seconds > 0.0 ? std::clamp(1.0 - elapsed / options_.lost_stop_seconds, 0.0, 1.0) : 0.0;
    const double speed = lost_speed_ * share;
    step.steering = speed != 0.0 ? "taught" : "none";
    double turn = speed != 0.0 ? TaughtTurnRate(position_, speed) : 0.0;
    if (tracking_ && tracking_->started()) {
      // The estimate goes on with the robot's motion (reported standing too): it steers while the robot slows down.
      const PathLocation at = tracking_->Locate();
      step.lateral_estimate = at.lateral;
      step.heading_error_estimate = at.heading_error;
      step.arc_estimate = at.s;
      if (speed != 0.0) {
        turn = PathFollowingTurnRate(at, speed, options_.convergence_distance);
        step.steering = "tracker";
      }
    }
    return finish(search({speed, turn}), ControllerState::kLost);
  }

  const double speed = NominalSpeed(position_);
  step.heading_offset = heading_offset;
  search({});  // usable: the search, if any, is over
  if (tracking_ && tracking_->started()) {
    const PathLocation at = tracking_->Locate();
    step.lateral_estimate = at.lateral;
    step.heading_error_estimate = at.heading_error;
    step.arc_estimate = at.s;
    // The goal is the goal key image's (above); an estimate well past the end of the path stops the robot too, where
    // the localizer places the robot on the last stretch (odometry alone ended runs half-way).
    if (position_ >= last - 1 && at.s >= tracking_->path_length() - 1e-6 && PastTheEnd(tracking_->pose()) > 0.5) {
      reached_goal_ = true;
      return finish({}, ControllerState::kReachedGoal);
    }
    if (std::abs(at.heading_error) > options_.turn_in_place_deg * M_PI / 180.0) {
      step.steering = "turn in place";
      return finish({0.0, -options_.heading_gain * at.heading_error}, ControllerState::kTurning);
    }
    step.steering = "tracker";
    return finish({speed, PathFollowingTurnRate(at, speed, options_.convergence_distance)},
                  ControllerState::kFollowing);
  }
  // The target key image lies ahead by what remains of this stretch, and the path turns by what the teach run
  // turned over it: on the taught path the heading offset is minus that turn and the line angle half of it (the
  // chord of an arc). Steering to zero them unaltered would cut every corner.
  const double remaining_turn = RemainingTurn(position_, localization.progress);
  const double heading_error = heading_offset + remaining_turn;
  double turn = TaughtTurnRate(position_, speed) - options_.heading_gain * heading_error;
  step.steering = "bearnav";
  const bool backwards = route_.segments[std::min(position_, last - 1)].backwards;
  // The servo law, and the tracker's on a route without teach odometry.
  const bool servo = options_.law == ControlLaw::kServo || (options_.law == ControlLaw::kTracker && !tracking_);
  if (servo && !backwards) {
    // The line angle (beta) from the target's pose where its translation is known and its rotation agrees with the
    // heading (a pose whose rotation is off has no better a translation), each frame's capped, then smoothed.
    const TargetBearing target =
        localization.translation_known ? BearingToKey(TargetComparison(localization).pose) : TargetBearing{};
    if (target.valid &&
        std::abs(WrapAngle(target.key_heading + heading_offset)) <= options_.pose_agreement_deg * M_PI / 180.0) {
      step.bearing = target.bearing;
      step.line_angle = target.line_angle();
      constexpr double kMaxLineAngle = 0.5;  // radians: beyond, a measurement is more likely wrong than right
      const double measured = std::clamp(target.line_angle(), -kMaxLineAngle, kMaxLineAngle);
      const double weight = line_angle_ && options_.line_filter_seconds > 0.0
                                ? 1.0 - std::exp(-(time - line_angle_time_) / options_.line_filter_seconds)
                                : 1.0;
      line_angle_ = line_angle_ ? *line_angle_ + weight * (measured - *line_angle_) : measured;
      line_angle_time_ = time;
    }
    // A line angle older than a few filter time constants is forgotten: the heading law steers until a new one.
    if (line_angle_ && time - line_angle_time_ > 3.0 * options_.line_filter_seconds + 0.5) line_angle_.reset();
    if (line_angle_) {
      // The polar-coordinate law of a unicycle parking on the key image's line, w = k_a alpha + k_b beta, with
      // alpha = psi - beta and psi (the key image's heading) = -heading offset: the heading term from the
      // features' heading, the line term from the filtered pose.
      turn = TaughtTurnRate(position_, speed) - options_.bearing_gain * heading_error +
             (options_.line_gain - options_.bearing_gain) * (*line_angle_ - 0.5 * remaining_turn);
      step.steering = "servo";
    }
  }
  if (std::abs(heading_offset) > options_.turn_in_place_deg * M_PI / 180.0) {
    step.steering = "turn in place";
    return finish({0.0, -options_.heading_gain * heading_offset}, ControllerState::kTurning);
  }
  return finish({speed, turn}, ControllerState::kFollowing);
}

}  // namespace vmap
