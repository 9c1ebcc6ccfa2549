#include "vmap/control/guidance_signals.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "vmap/core/numeric.h"

namespace vmap {

const KeyComparison& TargetComparison(const LocalizationResult& result) {
  return result.next_key >= 0 ? result.to_next : result.to_key;
}

double HeadingOffset(const LocalizationResult& result, double focal_px) {
  // heading > 0: the scene appears right of where the key image has it, i.e. the robot points left of it.
  if (std::isfinite(result.heading_deg)) return result.heading_deg * M_PI / 180.0;
  if (std::isfinite(result.heading_px) && focal_px > 0.0) return std::atan(result.heading_px / focal_px);
  return std::numeric_limits<double>::quiet_NaN();
}

TargetBearing BearingToKey(const RelativePose& pose) {
  TargetBearing bearing;
  if (!pose.valid) return bearing;
  // The key image's camera centre in the frame's camera coordinates (x right, y down, z forward): -R^T t.
  const cv::Vec3d centre = -(pose.R.t() * pose.t);
  if (!(centre[2] > 0.0)) return bearing;  // not ahead: a bearing to it would turn the robot around
  bearing.valid = true;
  bearing.bearing = -std::atan2(centre[0], centre[2]);
  // The key image's optical axis in the frame's coordinates, R^T (0, 0, 1).
  bearing.key_heading = -std::atan2(pose.R(2, 0), pose.R(2, 2));
  return bearing;
}

double ApparentLogScale(const std::vector<Correspondence>& verified, int min_pairs, double min_distance_px) {
  const int n = static_cast<int>(verified.size());
  std::vector<double> ratios;
  // Each match paired with a few others at fixed offsets: deterministic, and linear in the matches.
  constexpr int kOffsets[] = {1, 2, 3, 5, 8, 13, 21, 34};
  for (int offset : kOffsets) {
    if (offset >= n) break;
    for (int i = 0; i < n; ++i) {
      const int j = (i + offset) % n;
      const double key_height = std::abs(verified[i].p1.y - verified[j].p1.y);
      if (key_height < min_distance_px) continue;
      const double frame_height = std::abs(verified[i].p0.y - verified[j].p0.y);
      if (!(frame_height > 0.0)) continue;
      ratios.push_back(std::log(frame_height / key_height));
    }
  }
  if (static_cast<int>(ratios.size()) < min_pairs) return std::numeric_limits<double>::quiet_NaN();
  return Median(std::move(ratios));
}

std::vector<Correspondence> UndoFrameYaw(std::vector<Correspondence> verified, double yaw, double focal_px,
                                         cv::Point2d principal) {
  // The frame's ray (u, v, 1) in the key image's camera axes (x right, y down, z forward; the frame turned left
  // by yaw): (u cos yaw - sin yaw, v, u sin yaw + cos yaw).
  const double c = std::cos(yaw), s = std::sin(yaw);
  for (Correspondence& match : verified) {
    const double u = (match.p0.x - principal.x) / focal_px, v = (match.p0.y - principal.y) / focal_px;
    const double depth = u * s + c;
    if (!(depth > 0.0)) continue;  // behind the turned camera: left as it is (a turn of over 45 degrees)
    match.p0 = cv::Point2f(static_cast<float>(principal.x + focal_px * (u * c - s) / depth),
                           static_cast<float>(principal.y + focal_px * v / depth));
  }
  return verified;
}

}  // namespace vmap
