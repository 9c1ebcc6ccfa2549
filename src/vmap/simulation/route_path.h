#pragma once
// The path a simulated teach run drives, on the ground plane (REP 103: x forward, y left, metres): a polyline
// parametrised by arc length, with the built-in shapes of `vmap simulate --route` and a reader of waypoint
// CSVs.

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"

namespace vmap {

struct Pose2d {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;  // radians, counter-clockwise from +x
};

class RoutePath {
 public:
  // `points`: at least two, consecutive ones apart. `closed`: the path ends where it started (a loop's world
  // joins its corridor's ends).
  explicit RoutePath(std::vector<cv::Point2d> points, bool closed = false);
  RoutePath() : RoutePath({{0.0, 0.0}, {0.0, 0.0}}) {}  // a point at the origin

  double length() const { return cumulative_.back(); }
  bool closed() const { return closed_; }
  const std::vector<cv::Point2d>& points() const { return points_; }
  // Arc length at each point.
  const std::vector<double>& arc_lengths() const { return cumulative_; }
  // The point at arc length s (clamped to the path) and the path's direction there.
  Pose2d At(double s) const;

  struct Projection {
    double s = 0.0;        // arc length of the nearest point of the path
    double lateral = 0.0;  // signed distance to it, left of the path positive
  };
  // The nearest point of the path to `p`; within [s_min, s_max] of arc length when given (a loop passes a place
  // twice: the caller's progress tells which pass is meant). On a closed path, the segment from the last point back
  // to the first is part of it, at arc lengths from length() on.
  Projection Project(const cv::Point2d& p, double s_min = -std::numeric_limits<double>::infinity(),
                     double s_max = std::numeric_limits<double>::infinity()) const;

 private:
  std::vector<cv::Point2d> points_;
  std::vector<double> cumulative_;
  bool closed_ = false;
};

enum class RouteShape { kStraight, kTurn, kSCurve, kLoop };
inline constexpr EnumName<RouteShape> kRouteShapeNames[] = {{RouteShape::kStraight, "straight"},
                                                            {RouteShape::kTurn, "turn"},
                                                            {RouteShape::kSCurve, "s-curve"},
                                                            {RouteShape::kLoop, "loop"}};
RouteShape ParseRouteShape(const std::string& name);
std::string RouteShapeName(RouteShape shape);

// A route to teach and repeat and the corridor around it: the centre line of the world's corridor is the
// route extended straight by `extension` metres beyond both ends (end walls close it there), or, for a loop,
// the whole ring (closed), of which the route may drive less than all.
struct SimulatedRoute {
  std::string name;         // "straight", ..., or the CSV's file name
  RoutePath path;           // what the teach run drives, start to goal
  RoutePath corridor;       // the corridor's centre line
  double path_start = 0.0;  // arc length on `corridor` where `path` starts
};

// The built-in routes, starting at the origin heading along +x:
//   straight  10 m;
//   turn      4 m, a 90-degree left turn of radius 2.5 m, 4 m (11.9 m);
//   s-curve   2 m, 60 degrees left then 60 degrees right on radii of 3 m, 2 m (10.3 m);
//   loop      once round a ring of 3 m straights and half-circles of radius 2.5 m (21.7 m), stopping 2 m short of
//             the start, so that the goal is not where the repeat starts (19.7 m).
SimulatedRoute MakeRoute(RouteShape shape, double extension = 3.0);

// A route from a CSV of waypoints "x,y" (metres; a header line of non-numbers and lines starting with # are
// skipped), joined by straight segments. It is a loop (a closed corridor) when its last waypoint is its first.
// Throws InputError naming the file and line: fewer than two waypoints, a value that is not a finite number, a
// line without exactly two values (x,y; a third column such as a heading or a time is refused, not dropped),
// consecutive waypoints at the same place, a route longer than 2 km; and CheckCorridor's.
SimulatedRoute ReadRouteCsv(const std::filesystem::path& path, double corridor_width, double extension = 3.0);

// Checks that a corridor of `width` along `corridor` neither folds on a sharp turn nor overlaps itself; throws
// InputError saying where (`what` names the route in the message).
void CheckCorridor(const RoutePath& corridor, double width, const std::string& what);

}  // namespace vmap
