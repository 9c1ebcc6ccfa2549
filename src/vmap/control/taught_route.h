#pragma once
// The route a controller follows, as the teach run drove it: the key images in the order to reach them and,
// for each stretch between two of them, how long the teach run took, how far it went and how much it turned.
// That is the taught velocity profile of teach and repeat (Bearnav's "taught angular velocity"): the teach
// run's timestamps give the durations, its odometry (when the input had it) the lengths and turns, and without
// odometry the link's relative pose gives the turn.

#include <limits>
#include <vector>

#include "vmap/map/visual_map.h"
#include "vmap/sources/odometry.h"

namespace vmap {

// From route key image `from_key` to `to_key`.
struct TaughtSegment {
  int from_key = -1;
  int to_key = -1;
  bool backwards = false;  // against the teach run's direction (the robot reverses along it)
  // Seconds the teach run took between the two key images; NaN when the input had no timestamps.
  double duration = std::numeric_limits<double>::quiet_NaN();
  // Metres driven between them (teach odometry); NaN without odometry.
  double length = std::numeric_limits<double>::quiet_NaN();
  // How much the robot turned from `from_key` to `to_key` in the direction of the route, counter-clockwise seen
  // from above (radians, REP 103's yaw): from the teach odometry, else from the link's relative pose; NaN when
  // neither is known.
  double yaw_change = std::numeric_limits<double>::quiet_NaN();
  // How much larger to_key's scene appears in to_key than from from_key: the link's ApparentLogScale
  // (guidance_signals.h) with from_key as the frame, negative when the route drives towards the scene. How
  // much the scene grows over the stretch: a deep scene (a long corridor ahead) grows little. NaN when the link's
  // verified matches do not tell.
  double log_scale = std::numeric_limits<double>::quiet_NaN();
  // The link's verified matches: how much a frame taken at one of its key images shares with the other when the
  // appearance is the teach run's (0: unknown). A frame's verified matches against them tell how alike the
  // appearance is (RouteTracking: another season's comparisons give much noisier bearings).
  int verified = 0;

  double speed() const { return length / duration; }  // m/s; NaN unless both are known
};

struct TaughtRoute {
  std::vector<int> keys;                // key-image indices in the order to reach them (PlanRoute's keys)
  std::vector<TaughtSegment> segments;  // keys.size() - 1
  // The map camera's focal length in pixels (fx): turns pixel headings into angles; NaN without a camera.
  double focal_px = std::numeric_limits<double>::quiet_NaN();
  // The map camera's principal point (cx, cy) in pixels; NaN without a camera.
  cv::Point2d principal_point{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  // With teach odometry covering the route: each route key image's pose in the teach odometry's frame, and the
  // path the teach run drove from the first to the last, in the route's order (a route driven backwards lists
  // it backwards; yaw stays the teach run's heading). Empty without: the route is then known only up to scale.
  std::vector<OdometrySample> key_poses;
  std::vector<OdometrySample> path;

  bool metric() const { return !path.empty() && key_poses.size() == keys.size(); }
  int goal() const { return keys.empty() ? -1 : keys.back(); }
  // The route position of key image `key` (its index in `keys`), -1 when it is not on the route.
  int PositionOf(int key) const;
};

// The route `keys` of `map` (empty: every key image in map order) with its taught profile. `teach_odometry`
// (sorted by time, on the clock of the key images' timestamps) gives lengths and turns where it covers both
// key images of a segment. Throws InputError when `keys` names a key image the map does not have or two
// consecutive keys that no link joins.
TaughtRoute MakeTaughtRoute(const VisualMap& map, std::vector<int> keys = {},
                            const std::vector<OdometrySample>& teach_odometry = {});

// The turn of a link's pose, counter-clockwise seen from above (radians): the yaw of the second camera in the
// first one's frame (x right, y down, z forward), with X_to = R X_from + t.
double YawOfCameraRotation(const cv::Matx33d& R);

}  // namespace vmap
