#include "vmap/control/taught_route.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "vmap/control/guidance_signals.h"
#include "vmap/core/error.h"

namespace vmap {

int TaughtRoute::PositionOf(int key) const {
  const auto found = std::find(keys.begin(), keys.end(), key);
  return found == keys.end() ? -1 : static_cast<int>(found - keys.begin());
}

double YawOfCameraRotation(const cv::Matx33d& R) {
  // The second camera's optical axis in the first camera's frame is R^T (0, 0, 1); to the right (x > 0) is
  // clockwise seen from above.
  return -std::atan2(R(2, 0), R(2, 2));
}

namespace {

const Link* FindLink(const VisualMap& map, int a, int b) {
  for (const Link& link : map.links) {
    if ((link.from_key == a && link.to_key == b) || (link.from_key == b && link.to_key == a)) return &link;
  }
  return nullptr;
}

// Metres and radians (unwrapped) the odometry went between two times; NaN where it does not cover them.
std::pair<double, double> OdometryBetween(const std::vector<OdometrySample>& odometry, double t0, double t1) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (t1 < t0) std::swap(t0, t1);
  const std::optional<OdometrySample> start = InterpolateOdometry(odometry, t0);
  const std::optional<OdometrySample> end = InterpolateOdometry(odometry, t1);
  if (!start || !end) return {kNaN, kNaN};
  double length = 0.0, turn = 0.0;
  OdometrySample previous = *start;
  auto add = [&](const OdometrySample& sample) {
    length += std::hypot(sample.x - previous.x, sample.y - previous.y);
    turn += WrapAngle(sample.yaw - previous.yaw);
    previous = sample;
  };
  for (const OdometrySample& sample : odometry) {
    if (sample.timestamp > t0 && sample.timestamp < t1) add(sample);
  }
  add(*end);
  return {length, turn};
}

}  // namespace

TaughtRoute MakeTaughtRoute(const VisualMap& map, std::vector<int> keys,
                            const std::vector<OdometrySample>& teach_odometry) {
  const int num_keys = static_cast<int>(map.key_images.size());
  if (keys.empty()) {
    for (int k = 0; k < num_keys; ++k) keys.push_back(k);
  }
  TaughtRoute route;
  for (int key : keys) {
    if (key < 0 || key >= num_keys) {
      throw InputError("the route names key image " + std::to_string(key) + ", but the map has " +
                       std::to_string(num_keys) + " (0 to " + std::to_string(num_keys - 1) + ")");
    }
  }
  for (size_t i = 0; i + 1 < keys.size(); ++i) {
    const int a = keys[i], b = keys[i + 1];
    const Link* link = FindLink(map, a, b);
    if (link == nullptr) {
      throw InputError("the route goes from key image " + std::to_string(a) + " to " + std::to_string(b) +
                       ", which no link of the map joins; plan it with PlanRoute (vmap route)");
    }
    TaughtSegment segment;
    segment.from_key = a;
    segment.to_key = b;
    segment.backwards = b < a;
    const double t0 = map.key_images[a].timestamp, t1 = map.key_images[b].timestamp;
    if (t0 >= 0.0 && t1 >= 0.0) segment.duration = std::abs(t1 - t0);
    const double sign = segment.backwards ? -1.0 : 1.0;
    if (!teach_odometry.empty() && t0 >= 0.0 && t1 >= 0.0) {
      const auto [length, turn] = OdometryBetween(teach_odometry, std::min(t0, t1), std::max(t0, t1));
      segment.length = length;
      segment.yaw_change = sign * turn;
    }
    if (std::isnan(segment.yaw_change) && link->has_pose) segment.yaw_change = sign * YawOfCameraRotation(link->R);
    // The link's verified matches, from_key's point first (a link stored the other way round is read swapped).
    const int verified = std::clamp(link->num_verified, 0, static_cast<int>(link->correspondences.size()));
    std::vector<Correspondence> matches(link->correspondences.begin(), link->correspondences.begin() + verified);
    if (link->from_key != a) {
      for (Correspondence& match : matches) std::swap(match.p0, match.p1);
    }
    segment.log_scale = ApparentLogScale(matches);
    segment.verified = verified;
    route.segments.push_back(segment);
  }
  route.keys = std::move(keys);
  if (map.input.camera) {
    route.focal_px = map.input.camera->fx;
    route.principal_point = {map.input.camera->cx, map.input.camera->cy};
  }
  // The metric route: every key image's pose on the teach odometry, and the odometry between the first and last.
  if (!teach_odometry.empty()) {
    for (int key : route.keys) {
      const double t = map.key_images[key].timestamp;
      const std::optional<OdometrySample> pose = t >= 0.0 ? InterpolateOdometry(teach_odometry, t) : std::nullopt;
      if (!pose) {
        route.key_poses.clear();
        break;
      }
      route.key_poses.push_back(*pose);
    }
  }
  if (route.key_poses.size() == route.keys.size() && route.keys.size() >= 2) {
    const double t0 = route.key_poses.front().timestamp, t1 = route.key_poses.back().timestamp;
    const double first = std::min(t0, t1), last = std::max(t0, t1);
    route.path.push_back(*InterpolateOdometry(teach_odometry, first));
    for (const OdometrySample& sample : teach_odometry) {
      if (sample.timestamp > first && sample.timestamp < last) route.path.push_back(sample);
    }
    route.path.push_back(*InterpolateOdometry(teach_odometry, last));
    if (t1 < t0) std::reverse(route.path.begin(), route.path.end());
  }
  return route;
}

}  // namespace vmap
