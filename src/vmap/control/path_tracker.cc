#include "vmap/control/path_tracker.h"

#include <algorithm>
#include <cmath>

namespace vmap {

TaughtPath::TaughtPath(const std::vector<OdometrySample>& samples) {
  for (const OdometrySample& sample : samples) {
    // Samples where the robot stood still add nothing to the path (their yaw is the next one's).
    if (!samples_.empty() && std::hypot(sample.x - samples_.back().x, sample.y - samples_.back().y) < 1e-6) {
      samples_.back().yaw = sample.yaw;
      continue;
    }
    arc_.push_back(
        samples_.empty() ? 0.0 : arc_.back() + std::hypot(sample.x - samples_.back().x, sample.y - samples_.back().y));
    samples_.push_back(sample);
  }
}

double TaughtPath::ArcAtTime(double timestamp) const {
  if (samples_.empty()) return 0.0;
  // Samples are in the order driven: time goes up, or down for a route driven backwards.
  const bool increasing = samples_.back().timestamp >= samples_.front().timestamp;
  for (size_t i = 1; i < samples_.size(); ++i) {
    const double a = samples_[i - 1].timestamp, b = samples_[i].timestamp;
    if ((increasing && timestamp <= b) || (!increasing && timestamp >= b)) {
      const double w = b != a ? std::clamp((timestamp - a) / (b - a), 0.0, 1.0) : 0.0;
      return arc_[i - 1] + w * (arc_[i] - arc_[i - 1]);
    }
  }
  return arc_.back();
}

double TaughtPath::YawAt(double s) const {
  s = std::clamp(s, 0.0, length());
  size_t i = std::upper_bound(arc_.begin(), arc_.end(), s) - arc_.begin();
  i = std::clamp<size_t>(i, 1, samples_.size() - 1);
  const double span = arc_[i] - arc_[i - 1];
  const double w = span > 0.0 ? (s - arc_[i - 1]) / span : 0.0;
  return WrapAngle(samples_[i - 1].yaw + w * WrapAngle(samples_[i].yaw - samples_[i - 1].yaw));
}

PathLocation TaughtPath::Locate(const cv::Vec3d& pose, double s_min, double s_max) const {
  PathLocation best;
  if (samples_.size() < 2) return best;
  const cv::Point2d p(pose[0], pose[1]);
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < samples_.size(); ++i) {
    if (arc_[i] < s_min || arc_[i - 1] > s_max) continue;
    const cv::Point2d a(samples_[i - 1].x, samples_[i - 1].y), d = cv::Point2d(samples_[i].x, samples_[i].y) - a;
    const double span = std::sqrt(d.dot(d));
    double t = std::clamp((p - a).dot(d) / (span * span), 0.0, 1.0);
    const double s = std::clamp(arc_[i - 1] + t * span, s_min, s_max);
    t = (s - arc_[i - 1]) / span;
    const cv::Point2d q = a + t * d;
    const double distance = cv::norm(p - q);
    if (distance < best_distance) {
      best_distance = distance;
      best.s = s;
      best.point = q;
    }
  }
  const double yaw = YawAt(best.s);
  // Left of the taught heading (not of the direction driven: a route driven backwards keeps the teach heading).
  const cv::Point2d left(-std::sin(yaw), std::cos(yaw));
  best.lateral = (p - best.point).dot(left);
  best.heading_error = WrapAngle(pose[2] - yaw);
  constexpr double kHalfWindow = 0.2;  // metres either side over which the curvature is measured
  const double s0 = std::max(0.0, best.s - kHalfWindow), s1 = std::min(length(), best.s + kHalfWindow);
  if (s1 > s0) best.curvature = WrapAngle(YawAt(s1) - YawAt(s0)) / (s1 - s0);
  return best;
}

double PathFollowingTurnRate(const PathLocation& at, double speed, double convergence_distance) {
  const double L = convergence_distance;
  const double lateral = std::clamp(at.lateral, -L, L);
  // The curvature is along the direction driven (|speed|); the lateral offset is left of the taught heading,
  // so that it grows with the signed speed; the heading term damps whichever way the robot drives (|speed|).
  return std::abs(speed) * at.curvature - std::abs(speed) * (2.0 / L) * at.heading_error - speed * lateral / (L * L);
}

}  // namespace vmap
