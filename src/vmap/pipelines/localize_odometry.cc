#include "vmap/pipelines/localize_odometry.h"

#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/sources/recording_reader.h"

namespace vmap {

std::optional<OdometryProgress> OpenQueryOdometry(const std::string& path, const std::string& topic,
                                                  const std::string& query) {
  if (!path.empty()) return OdometryProgress(OdometryTrack(ReadOdometry(path, topic)));
  if (!IsRecording(query)) {
    if (!topic.empty()) {
      throw OptionError("odometry_topic",
                        "names a topic of the query recording, and '" + query +
                            "' is not a recording; give the odometry as a file (odometry)",
                        {"odometry"});
    }
    return std::nullopt;
  }
  const std::vector<std::string> topics = OdometryTopics(OpenRecording(query)->Topics());
  if (topics.empty() && topic.empty()) return std::nullopt;
  if (topics.size() > 1 && topic.empty()) {
    spdlog::warn(
        "'{}' has {} nav_msgs/Odometry topics; localizing without odometry (name one with "
        "--odometry-topic)",
        query, topics.size());
    return std::nullopt;
  }
  std::vector<OdometrySample> samples = ReadOdometryTopic(query, topic);
  spdlog::info("odometry        {} samples from {}", samples.size(), topic.empty() ? topics.front() : topic);
  return OdometryProgress(OdometryTrack(std::move(samples)));
}

void WriteTeachOdometry(const std::filesystem::path& map, const std::vector<OdometrySample>& samples) {
  WriteFileAtomically(map / kTeachOdometryFileName, OdometryCsv(samples));
}

std::vector<OdometrySample> ReadTeachOdometry(const std::filesystem::path& map, const std::string& given,
                                              const std::string& topic) {
  if (!given.empty()) return ReadOdometry(given, topic);
  // A map folder may come from elsewhere: its file is read only where it is a regular file inside it, as the map's
  // own files are.
  const std::string name = (map / kTeachOdometryFileName).string();
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::Open(map, kTeachOdometryFileName, &why_not);
  if (!file) {
    if (why_not == "is missing") return {};
    throw InputError(
        fmt::format("the map's {} {}; remove it, or give the teach odometry with --teach-odometry", name, why_not));
  }
  // Read through the descriptor that was checked: the path could name another file by now. Held whole, so bounded:
  // the CSV reader takes at most 10 million lines, well under this.
  constexpr std::uint64_t kMaxBytes = std::uint64_t{1} << 30;
  if (file->size() > kMaxBytes) {
    throw InputError(
        fmt::format("the map's {} is larger than 1 GiB; remove it, or give the teach odometry with "
                    "--teach-odometry",
                    name));
  }
  std::string text;
  if (!file->ReadAll(&text)) {
    throw InputError(
        fmt::format("cannot read the map's {}; remove it, or give the teach odometry with --teach-odometry", name));
  }
  std::istringstream in(text);
  return ParseOdometryCsv(in, name);
}

std::string OdometryCsvColumns() { return ",odometry_x,odometry_y,odometry_yaw,odometry_distance,key_distance"; }

std::string OdometryCsvCells(const FrameOdometry& odometry) {
  if (!odometry.valid) return ",,,,,";
  return fmt::format(",{:.6f},{:.6f},{:.6f},{:.6f},{}", odometry.pose.x, odometry.pose.y, odometry.pose.yaw,
                     odometry.distance,
                     std::isfinite(odometry.key_distance) ? fmt::format("{:.6f}", odometry.key_distance) : "");
}

nlohmann::json OdometryJson(int frame, const FrameOdometry& odometry) {
  auto number = [](double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr); };
  if (!odometry.valid)
    return {{"frame", frame}, {"x", nullptr},        {"y", nullptr},
            {"yaw", nullptr}, {"distance", nullptr}, {"key_distance", nullptr}};
  return {{"frame", frame},
          {"x", odometry.pose.x},
          {"y", odometry.pose.y},
          {"yaw", odometry.pose.yaw},
          {"distance", number(odometry.distance)},
          {"key_distance", number(odometry.key_distance)}};
}

}  // namespace vmap
