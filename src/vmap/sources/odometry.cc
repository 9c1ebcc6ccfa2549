#include "vmap/sources/odometry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/number_text.h"
#include "vmap/sources/message_buffer.h"

namespace vmap {

double WrapAngle(double radians) {
  const double wrapped = std::remainder(radians, 2.0 * M_PI);
  return wrapped <= -M_PI ? wrapped + 2.0 * M_PI : wrapped;
}

std::optional<OdometrySample> InterpolateOdometry(const std::vector<OdometrySample>& samples, double timestamp) {
  if (samples.empty() || !(timestamp >= samples.front().timestamp) || !(timestamp <= samples.back().timestamp)) {
    return std::nullopt;
  }
  const auto after = std::lower_bound(samples.begin(), samples.end(), timestamp,
                                      [](const OdometrySample& s, double t) { return s.timestamp < t; });
  if (after == samples.begin() || after->timestamp == timestamp) return *after;
  const OdometrySample& a = *(after - 1);
  const OdometrySample& b = *after;
  const double span = b.timestamp - a.timestamp;
  const double w = span > 0.0 ? (timestamp - a.timestamp) / span : 0.0;
  OdometrySample result;
  result.timestamp = timestamp;
  result.x = a.x + w * (b.x - a.x);
  result.y = a.y + w * (b.y - a.y);
  result.yaw = WrapAngle(a.yaw + w * WrapAngle(b.yaw - a.yaw));
  return result;
}

std::string OdometryCsv(const std::vector<OdometrySample>& samples) {
  std::string csv = "timestamp,x,y,yaw\n";
  for (const OdometrySample& sample : samples) {
    csv += fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}\n", sample.timestamp, sample.x, sample.y, sample.yaw);
  }
  return csv;
}

std::vector<OdometrySample> ReadOdometryCsv(const std::filesystem::path& path) {
  // Only a regular file, held whole, so bounded: neither a FIFO nor a device is ever read (a FIFO would block,
  // /dev/zero is one endless line). The parser takes at most 10 million lines, well under this size.
  std::istringstream in(
      ReadNamedFile(path, std::uint64_t{1} << 30, "odometry CSV", "give a file of timestamp,x,y,yaw lines"));
  return ParseOdometryCsv(in, path.string());
}

std::vector<OdometrySample> ParseOdometryCsv(std::istream& in, const std::string& name) {
  std::vector<OdometrySample> samples;
  std::string line;
  long number = 0;
  bool header_allowed = true;
  while (std::getline(in, line)) {
    if (++number > 10000000) throw InputError(fmt::format("odometry CSV '{}': more than 10 million lines", name));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream stream(line);
    for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
    double values[4];
    bool numbers = fields.size() >= 4;
    for (int i = 0; numbers && i < 4; ++i) {
      const std::optional<double> value = ParseNumber(fields[i]);
      numbers = value.has_value();
      values[i] = value.value_or(0.0);
    }
    if (!numbers) {
      if (header_allowed && fields.size() >= 4) {
        header_allowed = false;
        continue;
      }
      throw InputError(
          fmt::format("odometry CSV '{}' line {}: '{}' is not 'timestamp,x,y,yaw' (seconds, metres, "
                      "radians)",
                      name, number, line.substr(0, 80)));
    }
    header_allowed = false;
    for (double value : values) {
      if (!std::isfinite(value)) {
        throw InputError(fmt::format("odometry CSV '{}' line {}: a value is not a finite number", name, number));
      }
    }
    if (!samples.empty() && values[0] < samples.back().timestamp) {
      throw InputError(
          fmt::format("odometry CSV '{}' line {}: timestamp {} goes back from {}; sort the samples by time", name,
                      number, values[0], samples.back().timestamp));
    }
    samples.push_back({values[0], values[1], values[2], WrapAngle(values[3])});
  }
  if (samples.empty()) throw InputError(fmt::format("odometry CSV '{}' holds no timestamp,x,y,yaw line", name));
  return samples;
}

std::vector<std::string> OdometryTopics(const std::vector<RecordingTopic>& topics) {
  std::vector<std::string> names;
  for (const RecordingTopic& topic : topics) {
    if (NormalizedTypeName(topic.type) == kOdometryType) names.push_back(topic.name);
  }
  return names;
}

OdometrySample DecodeOdometryMessage(const uint8_t* data, size_t size, MessageEncoding encoding,
                                     const std::string& what) {
  MessageBuffer buffer(data, size, encoding, what);
  OdometrySample sample;
  sample.timestamp = ReadHeaderStamp(buffer, encoding);
  buffer.String();  // child_frame_id
  double position[3], orientation[4];
  buffer.F64Fixed(position, 3);
  buffer.F64Fixed(orientation, 4);  // x, y, z, w
  const double qx = orientation[0], qy = orientation[1], qz = orientation[2], qw = orientation[3];
  sample.x = position[0];
  sample.y = position[1];
  sample.yaw = std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
  if (!std::isfinite(sample.timestamp) || !std::isfinite(sample.x) || !std::isfinite(sample.y) ||
      !std::isfinite(sample.yaw)) {
    throw InputError(what + ": its pose is not finite numbers");
  }
  return sample;
}

std::vector<OdometrySample> ReadOdometryTopic(const std::string& recording, const std::string& topic) {
  const std::unique_ptr<RecordingReader> reader = OpenRecording(recording);
  const std::vector<std::string> topics = OdometryTopics(reader->Topics());
  std::string chosen = topic;
  if (chosen.empty()) {
    if (topics.size() != 1) {
      throw InputError(fmt::format("'{}' has {} nav_msgs/Odometry topics; name one with --odometry-topic{}", recording,
                                   topics.size(), topics.empty() ? " (or give a CSV with --odometry)" : ""));
    }
    chosen = topics.front();
  } else if (std::find(topics.begin(), topics.end(), chosen) == topics.end()) {
    throw InputError(fmt::format("'{}' has no nav_msgs/Odometry topic '{}'; `vmap info {}` lists its topics", recording,
                                 chosen, recording));
  }
  std::vector<OdometrySample> samples;
  RecordedMessage message;
  long index = 0;
  while (reader->Next({chosen}, &message)) {
    const std::string what = fmt::format("message {} of {} in '{}'", index++, chosen, recording);
    samples.push_back(DecodeOdometryMessage(message.data.data(), message.data.size(), reader->encoding(), what));
  }
  // Stored in receive order; the stamps say when each pose held.
  std::stable_sort(samples.begin(), samples.end(),
                   [](const OdometrySample& a, const OdometrySample& b) { return a.timestamp < b.timestamp; });
  if (samples.empty()) throw InputError(fmt::format("'{}': topic {} holds no message", recording, chosen));
  return samples;
}

std::vector<OdometrySample> ReadOdometry(const std::string& path, const std::string& topic) {
  if (IsRecording(path)) return ReadOdometryTopic(path, topic);
  if (!topic.empty()) {
    throw InputError(fmt::format("--odometry-topic names a topic of a recording, and '{}' is not one; drop it", path));
  }
  return ReadOdometryCsv(path);
}

OdometryTrack::OdometryTrack(std::vector<OdometrySample> samples) : samples_(std::move(samples)) {
  for (size_t i = 0; i < samples_.size(); ++i) {
    distance_.push_back(i == 0 ? 0.0
                               : distance_.back() +
                                     std::hypot(samples_[i].x - samples_[i - 1].x, samples_[i].y - samples_[i - 1].y));
  }
}

double OdometryTrack::DistanceAt(double timestamp) const {
  const std::optional<OdometrySample> at = At(timestamp);
  if (!at) return std::numeric_limits<double>::quiet_NaN();
  const auto after = std::lower_bound(samples_.begin(), samples_.end(), timestamp,
                                      [](const OdometrySample& s, double t) { return s.timestamp < t; });
  if (after == samples_.begin()) return 0.0;
  const size_t before = static_cast<size_t>(after - samples_.begin()) - 1;
  return distance_[before] + std::hypot(at->x - samples_[before].x, at->y - samples_[before].y);
}

}  // namespace vmap
