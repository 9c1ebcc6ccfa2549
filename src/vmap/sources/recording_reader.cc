#include "vmap/sources/recording_reader.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include <spdlog/spdlog.h>

#include "vmap/core/error.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {
bool IsRosbag2Folder(const fs::path& p) {
  std::error_code ec;
  if (!fs::is_directory(p, ec) || !fs::exists(p / "metadata.yaml", ec)) return false;
  for (const auto& entry : fs::directory_iterator(p, ec)) {
    const std::string extension = entry.path().extension().string();
    if (extension == ".db3" || extension == ".mcap") return true;
    if (extension == ".zstd" && entry.path().stem().extension() == ".db3") return true;  // --compression-mode file
  }
  return false;
}

// A rosbag2 folder written with the MCAP storage plugin holds one .mcap file per split; vmap reads the first
// of them when there is one, as the folder's recording.
std::string McapInFolder(const fs::path& p) {
  std::error_code ec;
  std::string found;
  for (const auto& entry : fs::directory_iterator(p, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".mcap" && (found.empty() || name < found)) found = name;
  }
  return found;
}
}  // namespace

bool IsRecording(const std::string& path) {
  const fs::path p(path);
  const std::string extension = p.extension().string();
  if (extension == ".bag" || extension == ".mcap" || extension == ".db3") return true;
  return IsRosbag2Folder(p);
}

std::unique_ptr<RecordingReader> OpenRecording(const std::string& path, const RecordingLimits& limits) {
  const fs::path p(path);
  const std::string extension = p.extension().string();
  std::error_code ec;
  const bool folder = fs::is_directory(p, ec);
  if (extension == ".bag" && !folder) return OpenRos1Bag(path, limits);
  if (extension == ".mcap" && !folder) return OpenMcap(path, limits);
  if (extension == ".db3" && !folder) return OpenRosbag2(path, limits);
  if (IsRosbag2Folder(p)) {
    const std::string mcap = McapInFolder(p);
    return mcap.empty() ? OpenRosbag2(path, limits) : OpenMcapInFolder(p, mcap, limits);
  }
  throw InputError("'" + path +
                   "' is not a recording vmap reads: give a ROS 1 .bag, a rosbag2 folder (metadata.yaml "
                   "and .db3 or .db3.zstd files) or an .mcap file");
}

std::string NormalizedTypeName(const std::string& type) {
  const size_t msg = type.find("/msg/");
  if (msg == std::string::npos) return type;
  return type.substr(0, msg) + "/" + type.substr(msg + 5);
}

std::vector<RecordingTopic> CountTopicsByReading(
    const std::function<bool(RecordedMessage* message, std::string* type)>& next) {
  std::map<std::string, RecordingTopic> by_topic;
  RecordedMessage message;
  std::string type;
  long counted = 0;
  for (;;) {
    try {
      if (!next(&message, &type)) break;
    } catch (const RecordingLimitExceeded&) {
      throw;  // not a recording cut short: one that asks too much, whatever came before
    } catch (const InputError& error) {
      // The frames before the damage are still read (RecordingSource warns again when it gets there).
      if (counted == 0) throw;
      spdlog::warn("{}; counting the {} messages before it", error.what(), counted);
      break;
    }
    ++counted;
    RecordingTopic& topic = by_topic[message.topic];
    if (topic.message_count++ == 0) {
      topic.name = message.topic;
      topic.type = type;
      topic.first_time_ns = message.log_time_ns;
      topic.last_time_ns = message.log_time_ns;
    }
    // Stored order need not be time order (MCAP chunks may overlap in time).
    topic.first_time_ns = std::min(topic.first_time_ns, message.log_time_ns);
    topic.last_time_ns = std::max(topic.last_time_ns, message.log_time_ns);
  }
  std::vector<RecordingTopic> list;
  for (auto& [name, topic] : by_topic) list.push_back(std::move(topic));
  return list;
}

}  // namespace vmap
