#include "vmap/localization/motion_pace.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace vmap {

double TeachFramesPerPosition(const std::vector<int>& route_source_indices) {
  if (route_source_indices.size() < 2) return 0.0;
  long apart = 0;
  for (size_t p = 1; p < route_source_indices.size(); ++p) {
    apart += std::abs(route_source_indices[p] - route_source_indices[p - 1]);
  }
  return static_cast<double>(apart) / static_cast<double>(route_source_indices.size() - 1);
}

double TeachSecondsPerPosition(const std::vector<double>& route_timestamps) {
  if (route_timestamps.size() < 2) return 0.0;
  int rising = 0, falling = 0;
  double apart = 0.0;
  for (size_t p = 1; p < route_timestamps.size(); ++p) {
    if (!(route_timestamps[p - 1] >= 0.0 && route_timestamps[p] >= 0.0)) return 0.0;  // NaN included
    const double step = route_timestamps[p] - route_timestamps[p - 1];
    rising += step > 0.0;
    falling += step < 0.0;
    apart += std::abs(step);
  }
  const int steps = static_cast<int>(route_timestamps.size()) - 1;
  if (rising != steps && falling != steps) return 0.0;
  const double mean = apart / steps;
  return std::isfinite(mean) ? mean : 0.0;
}

double TeachMetresPerPosition(const std::vector<double>& route_distances) {
  // The key images the odometry covers, by route position: a teach odometry that started a moment after the camera
  // (the ROS node's teach run), or paused, still spaces the others.
  int first = -1, last = -1;
  bool growing = true, shrinking = true;
  for (int p = 0; p < static_cast<int>(route_distances.size()); ++p) {
    if (!std::isfinite(route_distances[p])) continue;
    if (last >= 0) {
      growing = growing && route_distances[p] >= route_distances[last];
      shrinking = shrinking && route_distances[p] <= route_distances[last];
    } else {
      first = p;
    }
    last = p;
  }
  if (last <= first || (!growing && !shrinking)) return 0.0;
  // Distances along one odometry: the stretch's length is its ends' difference.
  return std::abs(route_distances[last] - route_distances[first]) / static_cast<double>(last - first);
}

int MotionStepsPerFrame(double travelled, double teach_per_position) {
  if (!(travelled > 0.0 && teach_per_position > 0.0)) return 1;
  // Bounded before rounding: a huge gap cannot overflow lround.
  const double steps = std::min(travelled / teach_per_position * kMotionStepsPerPosition, double{kMaxMotionSteps});
  return std::max(1, static_cast<int>(std::lround(steps)));
}

MotionPace::MotionPace(const std::vector<int>& route_source_indices, const std::vector<double>& route_timestamps,
                       int fixed_steps)
    : route_source_indices_(route_source_indices),
      teach_frames_per_position_(TeachFramesPerPosition(route_source_indices)),
      teach_seconds_per_position_(TeachSecondsPerPosition(route_timestamps)),
      fixed_steps_(fixed_steps) {}

void MotionPace::SetTeachDistances(const std::vector<double>& route_distances) {
  teach_metres_per_position_ = TeachMetresPerPosition(route_distances);
  route_teach_metres_.clear();
  route_teach_direction_ = 0;
  driven_from_.reset();
  if (!by_distance()) return;
  route_teach_metres_ = route_distances;
  // TeachMetresPerPosition found them all growing or all shrinking where they are known.
  auto known = [](double d) { return std::isfinite(d); };
  const double first = *std::find_if(route_distances.begin(), route_distances.end(), known);
  const double last = *std::find_if(route_distances.rbegin(), route_distances.rend(), known);
  route_teach_direction_ = last > first ? 1 : -1;
}

void MotionPace::Reset() {
  started_ = false;
  odometry_before_.reset();
  metres_driven_ = 0.0;
  ++driving_stretch_;
  driven_from_.reset();
}

std::optional<double> MotionPace::metres_driven() const {
  if (!odometry_before_ || !std::isfinite(odometry_before_->x + odometry_before_->y)) return std::nullopt;
  return metres_driven_;
}

namespace {

// The teach frames a run passed, whole: frames are counted, and the time between two frames jitters (rccar_room's
// 0.19 s at 0.1 s a teach frame is two frames).
long WholeFrames(double teach_frames_passed) {
  return std::isfinite(teach_frames_passed) ? std::lround(std::min(teach_frames_passed, 1e9)) : 0;
}

}  // namespace

int MotionPace::Steps(int source_index, double timestamp, const std::optional<OdometrySample>& odometry) {
  if (!(timestamp >= 0.0 && std::isfinite(timestamp))) timestamp = -1.0;
  const bool first = !started_;
  const double frames = static_cast<double>(source_index) - source_index_before_;
  const double seconds = timestamp - timestamp_before_;
  const bool timed = timestamp >= 0.0 && timestamp_before_ >= 0.0 && seconds > 0.0;
  const bool driven = odometry && odometry_before_;
  const double metres = driven ? std::hypot(odometry->x - odometry_before_->x, odometry->y - odometry_before_->y) : 0.0;
  if (driven && std::isfinite(metres)) {
    metres_driven_ += metres;
  } else {
    // A frame without odometry (or the first after one, or a pose that is not a number): a stretch begins.
    metres_driven_ = 0.0;
    ++driving_stretch_;
  }
  started_ = true;
  source_index_before_ = source_index;
  timestamp_before_ = timestamp;
  odometry_before_ = odometry;
  teach_frames_passed_ = 0;
  if (first) return 1;  // as the model was fitted: how far the run's first frame is from a frame before is not known
  if (fixed_steps_ > 0) return fixed_steps_;
  // The positions passed, in the unit the teach run is known in, and as teach frames.
  const auto passed = [&](double travelled, double teach_per_position) {
    if (travelled > 0.0 && std::isfinite(travelled)) {
      teach_frames_passed_ = WholeFrames(travelled / teach_per_position * teach_frames_per_position_);
    }
    return MotionStepsPerFrame(travelled, teach_per_position);
  };
  // A robot that stood still (metres 0) takes the one step every frame takes: the rules were fitted so.
  if (driven && std::isfinite(metres) && teach_metres_per_position_ > 0.0)
    return passed(metres, teach_metres_per_position_);
  if (timed && teach_seconds_per_position_ > 0.0) return passed(seconds, teach_seconds_per_position_);
  if (teach_frames_per_position_ > 0.0) return passed(std::max(frames, 1.0), teach_frames_per_position_);
  return 1;
}

namespace {

// The key images from the one after `position` on that the run may have reached since the frame before (at least 1):
// those within the teach frames it passed of the next one, where the frame before was at the furthest on the tracked
// segment. At most kMaxMotionSteps; 0 where nothing is known.
int ReachPassed(const std::vector<int>& route_source_indices, int position, long passed) {
  const int next = position + 1;
  const int last = static_cast<int>(route_source_indices.size()) - 1;
  if (position < 0 || next > last || passed <= 0) return 0;
  int reach = 1;
  while (next + reach <= last && reach < kMaxMotionSteps &&
         std::abs(route_source_indices[next + reach] - route_source_indices[next]) <= passed) {
    ++reach;
  }
  return reach;
}

}  // namespace

int MotionPace::Lookahead(int position, int lookahead) const {
  return std::max(lookahead, ReachPassed(route_source_indices_, position, teach_frames_passed_));
}

bool MotionPace::PassedLookahead(int position, int lookahead) const {
  return teach_frames_passed_ >= 2 && ReachPassed(route_source_indices_, position, teach_frames_passed_) >= lookahead;
}

std::optional<double> MotionPace::teach_metres_driven() const {
  const std::optional<double> metres = metres_driven();
  if (!metres || !driven_from_ || driven_from_->stretch != driving_stretch_) return std::nullopt;
  return driven_from_->teach_metres + route_teach_direction_ * (*metres - driven_from_->metres);
}

bool MotionPace::Covers(int position) const {
  return position >= 0 && position < static_cast<int>(route_teach_metres_.size()) &&
         std::isfinite(route_teach_metres_[position]);
}

void MotionPace::CountDrivenFrom(int position) {
  const std::optional<double> metres = metres_driven();
  if (!metres || !Covers(position)) {
    driven_from_.reset();
    return;
  }
  driven_from_ = DrivenFrom{route_teach_metres_[position], *metres, driving_stretch_};
}

void MotionPace::PlaceDrivenOnSegment(int position) {
  const std::optional<double> driven = teach_metres_driven();
  if (!driven || !Covers(position)) return;
  const int size = static_cast<int>(route_teach_metres_.size());
  const double at_key = route_teach_metres_[position];
  const double segment_end = position + 1 < size && std::isfinite(route_teach_metres_[position + 1])
                                 ? route_teach_metres_[position + 1]
                                 : at_key;
  const double low = std::min(at_key, segment_end), high = std::max(at_key, segment_end);
  driven_from_->teach_metres = std::clamp(*driven, low, high);
  driven_from_->metres = *metres_driven();
}

int MotionPace::NearestPosition(double teach_metres) const {
  int nearest = -1;
  double nearest_gap = std::numeric_limits<double>::infinity();
  for (int q = 0; q < static_cast<int>(route_teach_metres_.size()); ++q) {
    const double gap = std::abs(route_teach_metres_[q] - teach_metres);  // NaN (not covered) never nearer
    if (gap < nearest_gap) {
      nearest_gap = gap;
      nearest = q;
    }
  }
  return nearest;
}

int MotionPace::DrivenPosition() const {
  const std::optional<double> teach_metres = teach_metres_driven();
  return teach_metres ? NearestPosition(*teach_metres) : -1;
}

}  // namespace vmap
