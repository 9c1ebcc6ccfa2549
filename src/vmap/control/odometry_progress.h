#pragma once
// Odometry beside localization: for each localized frame, where the odometry puts the robot and how far it has
// driven since the frame reached its key image, the progress along the route in metres that teach-and-repeat
// systems switch key images by (Bearnav: odometry tells the distance along the route). `vmap localize` writes it
// when the query has odometry.

#include <limits>

#include "vmap/localization/localizer.h"
#include "vmap/sources/odometry.h"

namespace vmap {

struct FrameOdometry {
  bool valid = false;  // the odometry covers the frame's timestamp
  OdometrySample pose;
  double distance = std::numeric_limits<double>::quiet_NaN();  // metres from the odometry's first sample
  // Metres since the first frame localized at the current key image; NaN before one is.
  double key_distance = std::numeric_limits<double>::quiet_NaN();
};

class OdometryProgress {
 public:
  explicit OdometryProgress(OdometryTrack track) : track_(std::move(track)) {}
  // The frame's odometry; call once per frame, in order. Lost and uncertain frames keep the key image of the
  // last one steered by.
  FrameOdometry Update(const LocalizationResult& result);
  const OdometryTrack& track() const { return track_; }

 private:
  OdometryTrack track_;
  int key_ = -1;
  double key_reached_at_ = std::numeric_limits<double>::quiet_NaN();  // odometry distance
};

}  // namespace vmap
