#pragma once
// The tracker law's state (ControlLaw::kTracker): the robot's pose on a metric taught route, estimated from
// every localized frame (route_pose_estimator.h) and located on the taught path (path_tracker.h).

#include <optional>
#include <vector>

#include "vmap/control/path_tracker.h"
#include "vmap/control/route_pose_estimator.h"
#include "vmap/control/taught_route.h"
#include "vmap/localization/localizer.h"

namespace vmap {

// What one frame gave the estimate.
struct TrackingObservation {
  int headings = 0;      // heading measurements taken
  int bearings = 0;      // bearing measurements taken
  int scales = 0;        // key images' scales taken (how far before or past the key image)
  int refused = 0;       // measurements the gate refused
  int unassociated = 0;  // frames at a key image the estimate puts too far away to be seen
};

class RouteTracking {
 public:
  // `route` must be metric (TaughtRoute::metric()).
  explicit RouteTracking(const TaughtRoute& route, RoutePoseEstimatorOptions options = {});

  // The robot drove `distance` metres (negative: backwards) and turned `turn` radians since the last call.
  void Predict(double distance, double turn);
  // A usable frame (tracking or relocalized at a key image of the route): the robot's heading against the target
  // key image (the relative pose's rotation, or the features' heading, `focal_px` for pixel headings) and the
  // bearing to where the target was taken where the pose's translation is known. The first such frame starts
  // the estimate between key and next_key, at the localizer's progress.
  TrackingObservation Observe(const LocalizationResult& result, double focal_px);

  bool started() const { return estimator_.initialized(); }
  // Where the estimate is on the taught path (near where it was last: a loop passes a place twice).
  PathLocation Locate();
  cv::Vec3d pose() const { return estimator_.pose(); }
  cv::Matx33d covariance() const { return estimator_.covariance(); }
  double odometry_scale() const { return estimator_.odometry_scale(); }
  double path_length() const { return path_.length(); }
  void Reset();

 private:
  // Whether the comparison shares too little with its key image to measure as the teach run's appearance does:
  // fewer verified matches than RoutePoseEstimatorOptions::weak_share of the map link's.
  bool Weak(const KeyComparison& comparison, int target_position) const;

  TaughtRoute route_;
  RoutePoseEstimatorOptions options_;
  RoutePoseEstimator estimator_;
  TaughtPath path_;
  std::vector<double> key_arc_;  // arc length of each route key image on the path
  double arc_ = 0.0;             // where the robot was last located
};

}  // namespace vmap
