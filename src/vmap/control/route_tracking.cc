#include "vmap/control/route_tracking.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vmap/control/guidance_signals.h"

namespace vmap {

namespace {
// Metres along the path either way of the estimate within which a key image can be the one the robot sees.
constexpr double kAssociationWindow = 3.0;
}  // namespace

RouteTracking::RouteTracking(const TaughtRoute& route, RoutePoseEstimatorOptions options)
    : route_(route), options_(options), estimator_(options), path_(route.path) {
  for (const OdometrySample& key : route_.key_poses) key_arc_.push_back(path_.ArcAtTime(key.timestamp));
}

void RouteTracking::Reset() {
  estimator_.Reset();
  arc_ = 0.0;
}

void RouteTracking::Predict(double distance, double turn) { estimator_.Predict(distance, turn); }

TrackingObservation RouteTracking::Observe(const LocalizationResult& result, double focal_px) {
  TrackingObservation seen;
  const int key_position = route_.PositionOf(result.key);
  const int next_position = result.next_key >= 0 ? route_.PositionOf(result.next_key) : -1;
  const int target_position = next_position >= 0 ? next_position : key_position;
  if (key_position < 0 || target_position < 0) return seen;
  const OdometrySample& target = route_.key_poses[target_position];
  // The robot's heading against the target: from the relative pose's rotation where there is one (it holds
  // wherever the robot is) where the features' heading agrees with it; without a pose, from the features' heading,
  // which a sideways offset biases by its parallax, with a larger uncertainty.
  const RelativePose& pose = TargetComparison(result).pose;
  const double features = HeadingOffset(result, focal_px);
  const double rotation_offset = pose.valid ? -YawOfCameraRotation(pose.R) : std::numeric_limits<double>::quiet_NaN();
  // A rotation the features' heading contradicts is wrong or the features are biased: no heading from this frame.
  if (std::isfinite(rotation_offset) && std::isfinite(features) &&
      std::abs(WrapAngle(rotation_offset - features)) > options_.rotation_agreement) {
    return seen;
  }
  const bool rotation = std::isfinite(rotation_offset);
  const double offset = rotation ? rotation_offset : features;
  if (!std::isfinite(offset)) return seen;
  // The comparison's own evidence of how alike the appearance is: its verified matches against the link's.
  const bool weak = Weak(TargetComparison(result), target_position);
  const double heading_sigma = rotation
                                   ? (weak ? options_.weak_heading_sigma : options_.heading_sigma)
                                   : std::max(options_.feature_heading_sigma, weak ? options_.weak_heading_sigma : 0.0);
  if (!estimator_.initialized()) {
    // At the key image the localizer names, uncertain along the route by a stretch (a relocalization may be off
    // by a key image), across it by where a robot may start; the bearings that follow pull it in. Not at the
    // localizer's progress towards the next one: at the start of the simulator's runs it put the robot 0.2-0.6 m
    // ahead, the bearings (rare) did not pull that back, and the estimate turned into the bend early.
    const OdometrySample& key = route_.key_poses[key_position];
    const double spacing = std::hypot(target.x - key.x, target.y - key.y);
    const double along = std::max(0.5, options_.start_along_share * spacing);
    const double across = options_.start_lateral_sigma;
    const double c = std::cos(target.yaw), s = std::sin(target.yaw);
    const cv::Matx22d rotate(c, -s, s, c);
    const cv::Matx22d position = rotate * cv::Matx22d(along * along, 0, 0, across * across) * rotate.t();
    const double yaw_sigma = 2.0 * heading_sigma;
    const cv::Matx33d covariance(position(0, 0), position(0, 1), 0, position(1, 0), position(1, 1), 0, 0, 0,
                                 yaw_sigma * yaw_sigma);
    estimator_.InitializeWithCovariance({key.x, key.y, target.yaw + offset}, covariance);
    arc_ = key_arc_[key_position];
    return seen;
  }
  // A key image the estimate puts far from the robot is a localizer's mistake (a relocalization to a look-alike
  // place, a jump ahead): it says nothing of where the robot is. A bearing needs the key image ahead.
  const double ahead = key_arc_[target_position] - Locate().s;
  if (ahead < -kAssociationWindow || ahead > kAssociationWindow) {
    ++seen.unassociated;
    return seen;
  }
  const bool heading_taken = estimator_.UpdateHeading(target.yaw + offset, heading_sigma);
  (heading_taken ? seen.headings : seen.refused) += 1;
  // How far before or past the key image, from how large its scene appears against its growth over the link into
  // it (none at the route's start: the next link's growth is another scene's, and it held the estimate of an
  // s-curve repeat at the start while the robot drove 0.7 m). Not on a link driven backwards (the camera faces away
  // from the motion), nor on one that turns (RoutePoseEstimatorOptions::scale_max_turn).
  if (options_.scale_sigma > 0.0 && result.to_key.matched && key_position > 0) {
    const TaughtSegment& link = route_.segments[key_position - 1];
    const OdometrySample& key = route_.key_poses[key_position];
    // Seen with the key image's heading (the estimate's, measured well by the rotations): turned, one side of
    // the view is nearer than the other and the scale would read as a step along the route.
    const bool camera =
        focal_px > 0.0 && std::isfinite(route_.principal_point.x) && std::isfinite(route_.principal_point.y);
    const double log_scale =
        ApparentLogScale(camera ? UndoFrameYaw(result.to_key.verified, WrapAngle(estimator_.pose()[2] - key.yaw),
                                               focal_px, route_.principal_point)
                                : result.to_key.verified);
    const bool straight = std::abs(link.yaw_change) <= options_.scale_max_turn;  // false when NaN
    if (straight && !link.backwards && link.log_scale < 0.0 && link.length > 0.0 && std::isfinite(log_scale)) {
      // The scene's depth from the key image, from its growth over the link: depth / (depth + length) = scale.
      const double depth = link.length / std::expm1(-link.log_scale);
      const double sigma = Weak(result.to_key, key_position) ? options_.weak_scale_sigma : options_.scale_sigma;
      (estimator_.UpdateScale({key.x, key.y}, {std::cos(key.yaw), std::sin(key.yaw)}, depth, log_scale, sigma)
           ? seen.scales
           : seen.refused) += 1;
    }
  }
  // A bearing needs its pose's rotation taken: the translation comes from the same decomposition, and a rotation the
  // gate refuses is wrong, so is its translation. In the s-curve's bends (the key image ahead looking along a wall
  // seen obliquely) the bearings of poses whose heading was refused were off by +0.13 to +0.30 rad (median, 50
  // trials), against -0.02 to +0.09 where the heading was taken, and they pushed the estimate 0.15-0.2 m back
  // along the route (docs/drive.md).
  if (result.translation_known && ahead > 0.0 && heading_taken && rotation) {
    const TargetBearing bearing = BearingToKey(pose);
    if (bearing.valid) {
      const double sigma = weak ? options_.weak_bearing_sigma : options_.bearing_sigma;
      (estimator_.UpdateBearing({target.x, target.y}, bearing.bearing, sigma) ? seen.bearings : seen.refused) += 1;
    }
  }
  return seen;
}

bool RouteTracking::Weak(const KeyComparison& comparison, int target_position) const {
  // The link into the target (out of it at the route's start): what a frame of the teach run's appearance shares.
  if (route_.segments.empty()) return false;
  const TaughtSegment& link = route_.segments[std::max(target_position, 1) - 1];
  if (link.verified <= 0) return false;
  return comparison.num_verified < options_.weak_share * link.verified;
}

PathLocation RouteTracking::Locate() {
  const PathLocation at = path_.Locate(estimator_.pose(), arc_ - 1.0, arc_ + 2.0);
  arc_ = at.s;
  return at;
}

}  // namespace vmap
