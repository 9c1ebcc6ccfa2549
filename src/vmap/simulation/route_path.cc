#include "vmap/simulation/route_path.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>

#include <fmt/format.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/number_text.h"

namespace vmap {

RouteShape ParseRouteShape(const std::string& name) { return ParseEnum(kRouteShapeNames, name, "route"); }
std::string RouteShapeName(RouteShape shape) { return EnumToName(kRouteShapeNames, shape); }

RoutePath::RoutePath(std::vector<cv::Point2d> points, bool closed) : points_(std::move(points)), closed_(closed) {
  CV_Assert(points_.size() >= 2);
  cumulative_.push_back(0.0);
  for (size_t i = 1; i < points_.size(); ++i)
    cumulative_.push_back(cumulative_.back() + cv::norm(points_[i] - points_[i - 1]));
}

Pose2d RoutePath::At(double s) const {
  s = std::clamp(s, 0.0, length());
  size_t i = std::upper_bound(cumulative_.begin(), cumulative_.end(), s) - cumulative_.begin();
  i = std::clamp<size_t>(i, 1, points_.size() - 1);
  while (i + 1 < points_.size() && cumulative_[i] == cumulative_[i - 1]) ++i;
  const cv::Point2d a = points_[i - 1], b = points_[i];
  const double span = cumulative_[i] - cumulative_[i - 1];
  const double w = span > 0.0 ? (s - cumulative_[i - 1]) / span : 0.0;
  const cv::Point2d p = a + w * (b - a);
  return {p.x, p.y, std::atan2(b.y - a.y, b.x - a.x)};
}

RoutePath::Projection RoutePath::Project(const cv::Point2d& p, double s_min, double s_max) const {
  Projection best;
  double best_distance = std::numeric_limits<double>::infinity();
  // A closed path's last segment joins its last point to its first, from arc length length() on: without it, a
  // point beside that segment was measured from the nearest corner (a CSV loop's last side "left the corridor").
  const size_t segments = points_.size() - (closed_ ? 0 : 1);
  for (size_t i = 1; i <= segments; ++i) {
    const cv::Point2d a = points_[i - 1], d = points_[i % points_.size()] - a;
    const double start = cumulative_[i - 1], span = d.dot(d);
    if (start + std::sqrt(span) < s_min || start > s_max || span <= 0.0) continue;
    double w = std::clamp((p - a).dot(d) / span, 0.0, 1.0);
    const double s = std::clamp(start + w * std::sqrt(span), s_min, s_max);
    w = (s - start) / std::sqrt(span);
    const cv::Point2d q = a + w * d;
    const double distance = cv::norm(p - q);
    if (distance < best_distance) {
      best_distance = distance;
      best.s = s;
      // Left of the direction of travel: positive cross product.
      best.lateral = (d.x * (p.y - a.y) - d.y * (p.x - a.x)) >= 0.0 ? distance : -distance;
    }
  }
  return best;
}

namespace {

// Appends an arc of `radius` turning by `turn` radians (left positive) from the last point, whose heading is
// `heading`, in steps of at most 5 degrees; returns the new heading.
double AppendArc(std::vector<cv::Point2d>& points, double heading, double radius, double turn) {
  const cv::Point2d start = points.back();
  const double side = turn > 0 ? 1.0 : -1.0;  // the centre is left of a left turn
  const cv::Point2d centre = start + radius * side * cv::Point2d(-std::sin(heading), std::cos(heading));
  const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(turn) / (5.0 * M_PI / 180.0))));
  const double start_angle = std::atan2(start.y - centre.y, start.x - centre.x);
  for (int k = 1; k <= steps; ++k) {
    const double angle = start_angle + turn * k / steps;
    points.push_back(centre + radius * cv::Point2d(std::cos(angle), std::sin(angle)));
  }
  return heading + turn;
}

void AppendStraight(std::vector<cv::Point2d>& points, double heading, double length) {
  points.push_back(points.back() + length * cv::Point2d(std::cos(heading), std::sin(heading)));
}

// The route with the corridor extended straight beyond both ends.
SimulatedRoute OpenRoute(std::string name, std::vector<cv::Point2d> points, double extension) {
  SimulatedRoute route{std::move(name), RoutePath(points), RoutePath(points), extension};
  std::vector<cv::Point2d> corridor;
  const Pose2d start = route.path.At(0.0), end = route.path.At(route.path.length());
  corridor.push_back(cv::Point2d(start.x, start.y) - extension * cv::Point2d(std::cos(start.yaw), std::sin(start.yaw)));
  corridor.insert(corridor.end(), points.begin(), points.end());
  corridor.push_back(cv::Point2d(end.x, end.y) + extension * cv::Point2d(std::cos(end.yaw), std::sin(end.yaw)));
  route.corridor = RoutePath(corridor);
  if (extension <= 0.0) route.corridor = RoutePath(points);
  return route;
}

}  // namespace

SimulatedRoute MakeRoute(RouteShape shape, double extension) {
  std::vector<cv::Point2d> points = {{0.0, 0.0}};
  const std::string name = RouteShapeName(shape);
  double heading = 0.0;
  switch (shape) {
    case RouteShape::kStraight:
      AppendStraight(points, heading, 10.0);
      break;
    case RouteShape::kTurn:
      AppendStraight(points, heading, 4.0);
      heading = AppendArc(points, heading, 2.5, M_PI / 2);
      AppendStraight(points, heading, 4.0);
      break;
    case RouteShape::kSCurve:
      AppendStraight(points, heading, 2.0);
      heading = AppendArc(points, heading, 3.0, M_PI / 3);
      heading = AppendArc(points, heading, 3.0, -M_PI / 3);
      AppendStraight(points, heading, 2.0);
      break;
    case RouteShape::kLoop: {
      AppendStraight(points, heading, 3.0);
      heading = AppendArc(points, heading, 2.5, M_PI);
      AppendStraight(points, heading, 3.0);
      AppendArc(points, heading, 2.5, M_PI);
      points.back() = points.front();  // exactly closed
      RoutePath ring(std::vector<cv::Point2d>(points.begin(), points.end() - 1), true);
      // The route: round the ring, stopping 2 m short of the start.
      const double stop = ring.length() + cv::norm(points.back() - points[points.size() - 2]) - 2.0;
      std::vector<cv::Point2d> route;
      for (size_t i = 0; i < ring.points().size() && ring.arc_lengths()[i] < stop; ++i)
        route.push_back(ring.points()[i]);
      const Pose2d end = RoutePath(points).At(stop);
      route.emplace_back(end.x, end.y);
      return {name, RoutePath(route), ring, 0.0};
    }
  }
  return OpenRoute(name, points, extension);
}

void CheckCorridor(const RoutePath& corridor, double width, const std::string& what) {
  const std::vector<cv::Point2d>& p = corridor.points();
  const int n = static_cast<int>(p.size());
  const double half = 0.5 * width;
  // Sharp turns: the inner wall's corner at each vertex is set back half * tan(turn / 2) along both segments;
  // two set-backs that overlap on one segment fold the wall.
  auto turn_at = [&](int i) {
    if (!corridor.closed() && (i == 0 || i == n - 1)) return 0.0;
    const cv::Point2d a = p[(i - 1 + n) % n], b = p[i], c = p[(i + 1) % n];
    return std::remainder(std::atan2(c.y - b.y, c.x - b.x) - std::atan2(b.y - a.y, b.x - a.x), 2 * M_PI);
  };
  const int segments = corridor.closed() ? n : n - 1;
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % n;
    const double ti = std::abs(turn_at(i)), tj = std::abs(turn_at(j));
    const double length = cv::norm(p[j] - p[i]);
    if (ti > 0.75 * M_PI || tj > 0.75 * M_PI || half * (std::tan(ti / 2) + std::tan(tj / 2)) > length + 1e-9) {
      const int at = ti >= tj ? i : j;
      throw InputError(fmt::format(
          "{}: the route turns too sharply at ({:.2f}, {:.2f}) for a corridor {} m wide (its inner wall would "
          "fold); round the turn with more waypoints, or give a narrower --corridor-width",
          what, p[at].x, p[at].y, width));
    }
  }
  // Overlaps: points every 0.25 m; two more than 2 widths apart along the corridor must stay a width apart.
  std::vector<cv::Point2d> samples;
  std::vector<double> arc;
  const double ring = corridor.length() + (corridor.closed() ? cv::norm(p.back() - p.front()) : 0.0);
  for (double s = 0.0; s <= corridor.length(); s += 0.25) {
    const Pose2d pose = corridor.At(s);
    samples.emplace_back(pose.x, pose.y);
    arc.push_back(s);
  }
  for (size_t a = 0; a < samples.size(); ++a) {
    for (size_t b = a + 1; b < samples.size(); ++b) {
      double along = arc[b] - arc[a];
      if (corridor.closed()) along = std::min(along, ring - along);
      if (along <= 2.0 * width) continue;
      if (cv::norm(samples[a] - samples[b]) < width) {
        throw InputError(fmt::format(
            "{}: the route comes back within {} m (the corridor's width) of itself: at ({:.2f}, {:.2f}) and "
            "({:.2f}, {:.2f}), {:.1f} m further on; corridors would overlap. Move the waypoints apart or give a "
            "narrower --corridor-width",
            what, width, samples[a].x, samples[a].y, samples[b].x, samples[b].y, along));
      }
    }
  }
}

SimulatedRoute ReadRouteCsv(const std::filesystem::path& path, double corridor_width, double extension) {
  const std::string name = path.string();
  // Only a regular file, held whole, so bounded (a FIFO would block, /dev/zero is one endless line): 100,000 lines of
  // waypoints are well under this size.
  std::istringstream in(
      ReadNamedFile(path, std::uint64_t{16} << 20, "route CSV", "give a file of x,y waypoints in metres"));
  std::vector<cv::Point2d> points;
  std::vector<int> lines;
  std::string line;
  int number = 0;
  bool header_allowed = true;
  while (std::getline(in, line)) {
    ++number;
    if (number > 100000) throw InputError(fmt::format("route CSV '{}': more than 100000 lines", name));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte order mark
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream stream(line);
    std::string field;
    while (std::getline(stream, field, ',')) fields.push_back(field);
    const std::optional<double> read_x = fields.size() >= 2 ? ParseNumber(fields[0]) : std::nullopt;
    const std::optional<double> read_y = fields.size() >= 2 ? ParseNumber(fields[1]) : std::nullopt;
    if (!read_x || !read_y) {
      if (header_allowed && fields.size() >= 2) {  // a header line such as "x,y"
        header_allowed = false;
        continue;
      }
      // Quoted with escapes ({:?}): a binary file's bytes are not sent to the terminal.
      throw InputError(fmt::format("route CSV '{}' line {}: {:?} is not 'x,y' (two numbers in metres)", name, number,
                                   line.substr(0, 80)));
    }
    header_allowed = false;
    if (fields.size() > 2) {
      // Read as x,y, a "t,x,y" or "id,x,y" file would be a different route without a word; the direction of
      // travel comes from the waypoints, so a heading column has nothing to add.
      throw InputError(fmt::format(
          "route CSV '{}' line {}: {} values; a route CSV holds two, x,y in metres (keep only those columns, "
          "e.g. cut -d, -f1,2)",
          name, number, fields.size()));
    }
    const double x = *read_x, y = *read_y;
    if (!std::isfinite(x) || !std::isfinite(y) || std::abs(x) > 1e4 || std::abs(y) > 1e4) {
      throw InputError(
          fmt::format("route CSV '{}' line {}: waypoint ({}, {}) is not a finite number of metres within "
                      "10 km of the origin",
                      name, number, fields[0], fields[1]));
    }
    if (!points.empty() && cv::norm(cv::Point2d(x, y) - points.back()) < 1e-3) {
      throw InputError(
          fmt::format("route CSV '{}' line {}: waypoint ({}, {}) lies within 1 mm of the one before; remove it", name,
                      number, x, y));
    }
    points.emplace_back(x, y);
    lines.push_back(number);
  }
  if (points.size() < 2) {
    throw InputError(
        fmt::format("route CSV '{}' has {} waypoint(s); a route needs at least two x,y lines", name, points.size()));
  }
  const RoutePath waypoints(points);
  if (waypoints.length() > 2000.0) {
    throw InputError(fmt::format("route CSV '{}' is {:.0f} m long; the simulator takes routes up to 2 km", name,
                                 waypoints.length()));
  }
  const bool closed = points.size() >= 4 && cv::norm(points.back() - points.front()) < 1e-3;
  SimulatedRoute route;
  if (closed) {
    route = {name, waypoints, RoutePath(std::vector<cv::Point2d>(points.begin(), points.end() - 1), true), 0.0};
  } else {
    route = OpenRoute(name, points, extension);
  }
  CheckCorridor(route.corridor, corridor_width, "route CSV '" + name + "'");
  return route;
}

}  // namespace vmap
