#pragma once
// What a steering law reads from one frame's localization: the heading against the target key image, the
// bearing to the target's position and its heading where the relative pose has a translation to trust, and
// how large the target's scene appears (how near it is).
//
// Angles are REP 103's: counter-clockwise seen from above is positive; the camera looks along the robot's
// forward axis.

#include <limits>
#include <vector>

#include "vmap/geometry/relative_pose.h"
#include "vmap/localization/localizer.h"
#include "vmap/map/visual_map.h"

namespace vmap {

// The comparison a controller steers by: against next_key, or against key at the route's end (as the
// localizer's heading_px is).
const KeyComparison& TargetComparison(const LocalizationResult& result);

// The robot's heading relative to the target key image's (radians, counter-clockwise positive: the robot
// points left of where the key image looked), from the heading in degrees, or in pixels over `focal_px`
// without a camera; NaN without a heading.
double HeadingOffset(const LocalizationResult& result, double focal_px);

// Where the target key image was taken, seen from the robot, from a relative pose (X_key = R X_frame + t).
struct TargetBearing {
  bool valid = false;  // a pose with the key image ahead of the camera
  // Bearing of the key image's position from the robot's heading (alpha; left positive).
  double bearing = std::numeric_limits<double>::quiet_NaN();
  // The key image's heading relative to the robot's (psi; left positive).
  double key_heading = std::numeric_limits<double>::quiet_NaN();
  // The angle between the key image's heading and the robot-to-key direction (beta = psi - alpha): 0 on the
  // line the key image looked along, positive when the robot is left of it.
  double line_angle() const { return key_heading - bearing; }
};
TargetBearing BearingToKey(const RelativePose& pose);

// log of how much larger the scene appears in the frame than in the key image: the median, over pairs of
// verified matches, of log(vertical distance in the frame / vertical distance in the key image) (p0 the frame,
// p1 the key image, as in KeyComparison::verified). Below 0 behind the key image (the scene still smaller),
// about 0 at it, above 0 past it; NaN with fewer than `min_pairs` pairs at least `min_distance_px` apart
// vertically in the key image. Vertical distances only: for a camera that looks along the route (upright, as a
// robot's), a point's image height is its height over its depth, and a step sideways changes no depth; a
// horizontal distance also changes with the angle an oblique surface is seen at, so a robot beside the path
// would look ahead of or behind where it is.
double ApparentLogScale(const std::vector<Correspondence>& verified, int min_pairs = 20, double min_distance_px = 20.0);

// The matches with each frame point (p0) moved to where a camera at the frame's place, but with the key image's
// heading, would see it (the rotation's homography; a pinhole camera of focal length `focal_px` and principal
// point `principal`). `yaw`: the frame's heading relative to the key image's (radians, counter-clockwise seen
// from above: the robot points left of where the key image looked). A turned camera sees one side of the image
// nearer than the other, which ApparentLogScale would read as a step along the route.
std::vector<Correspondence> UndoFrameYaw(std::vector<Correspondence> verified, double yaw, double focal_px,
                                         cv::Point2d principal);

}  // namespace vmap
