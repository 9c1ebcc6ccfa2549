#pragma once
// Wheel (or visual-inertial) odometry of a robot: its pose in the plane of an odometry frame, over time, as
// nav_msgs/Odometry gives it (REP 103: x forward, y left, yaw counter-clockwise seen from above). A repeat run's
// odometry lets a controller tell the distance travelled between frames; a teach run's gives the taught speed
// and turn rate of each stretch of the route (control/taught_route.h).

#include <cstdint>
#include <filesystem>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "vmap/sources/odometry_sample.h"
#include "vmap/sources/recording_reader.h"

namespace vmap {

// The pose at `timestamp`, interpolated linearly between the two samples around it (yaw along the shorter
// arc); nullopt outside [first, last] sample or for an empty list. `samples` must be sorted by timestamp.
std::optional<OdometrySample> InterpolateOdometry(const std::vector<OdometrySample>& samples, double timestamp);

// The angle wrapped into (-pi, pi].
double WrapAngle(double radians);

inline constexpr const char* kOdometryType = "nav_msgs/Odometry";

// A CSV of timestamped poses, "timestamp,x,y,yaw" (seconds, metres, radians; a header line of names and lines
// starting with # are skipped; more columns after the fourth are ignored). Throws InputError naming the file
// and line: a value that is not a finite number, fewer than four columns, timestamps that go backwards, no
// sample at all, more than 10 million lines.
std::vector<OdometrySample> ReadOdometryCsv(const std::filesystem::path& path);
// The same CSV's text from `in`, `name` naming it in errors (a file opened already: a map folder's, read through the
// descriptor that checked it).
std::vector<OdometrySample> ParseOdometryCsv(std::istream& in, const std::string& name);
// The text of such a CSV (with its header line), every value to full precision: ReadOdometryCsv reads the same
// samples back.
std::string OdometryCsv(const std::vector<OdometrySample>& samples);

// The nav_msgs/Odometry topics of a recording (RecordingReader::Topics).
std::vector<std::string> OdometryTopics(const std::vector<RecordingTopic>& topics);

// The samples of a recording's nav_msgs/Odometry topic `topic` ("": its only one), by header stamp: the pose's
// position x, y and its orientation's yaw (about z). Throws InputError naming the recording and the topic when
// there is no such topic (or several, and none named), or a message is malformed.
std::vector<OdometrySample> ReadOdometryTopic(const std::string& recording, const std::string& topic);

// A nav_msgs/Odometry message, `what` naming it in errors.
OdometrySample DecodeOdometryMessage(const uint8_t* data, size_t size, MessageEncoding encoding,
                                     const std::string& what);

// Odometry read where it is: a recording's topic (`topic`, "" for its only one) or a CSV file.
std::vector<OdometrySample> ReadOdometry(const std::string& path, const std::string& topic);

// Samples with the distance driven along them, for looking up many times.
class OdometryTrack {
 public:
  explicit OdometryTrack(std::vector<OdometrySample> samples);  // sorted by timestamp
  std::optional<OdometrySample> At(double timestamp) const { return InterpolateOdometry(samples_, timestamp); }
  // Metres driven from the first sample to `timestamp` (interpolated); NaN outside the samples.
  double DistanceAt(double timestamp) const;
  const std::vector<OdometrySample>& samples() const { return samples_; }

 private:
  std::vector<OdometrySample> samples_;
  std::vector<double> distance_;  // at each sample
};

}  // namespace vmap
