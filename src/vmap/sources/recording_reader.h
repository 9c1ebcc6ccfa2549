#pragma once
// Robot recordings (ROS 1 bags, rosbag2 sqlite3 folders, MCAP files) seen as one thing: a list of topics and a
// stream of serialized messages, in the order they are stored. The container formats differ; the messages
// do not (recording_messages.h decodes them).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "vmap/sources/recording_limits.h"

namespace vmap {

// How a recording's messages are serialized: ROS 1 (packed little-endian) or ROS 2's CDR (aligned, with a
// 4-byte encapsulation header).
enum class MessageEncoding { kRos1, kCdr };

enum class RecordingFormat { kRos1Bag, kRosbag2, kMcap };

struct RecordingTopic {
  std::string name;
  std::string type;  // as stored: "sensor_msgs/Image" (ROS 1) or "sensor_msgs/msg/Image" (ROS 2)
  long message_count = 0;
  int64_t first_time_ns = 0;  // log (receive) times of its first and last message
  int64_t last_time_ns = 0;
};

struct RecordedMessage {
  std::string topic;
  // The message's type as the recording names it for the message's connection or channel: a topic may have several,
  // of other types (a publisher that changed type during the recording). Empty where the format names it per topic
  // only (rosbag2).
  std::string type;
  int64_t log_time_ns = 0;
  uint64_t offset = 0;  // where the message (or its chunk) is in the file: for messages naming the damage
  std::vector<uint8_t> data;
};

class RecordingReader {
 public:
  virtual ~RecordingReader() = default;
  // Every topic with its message count. May read the whole recording (the formats' indexes are optional and
  // a truncated recording has none), so callers ask once.
  virtual std::vector<RecordingTopic> Topics() = 0;
  // The next message on one of `topics` (all when empty), in stored order; false at the end. Throws
  // InputError naming the file and offset when the recording is damaged there.
  virtual bool Next(const std::set<std::string>& topics, RecordedMessage* message) = 0;
  // Starts again from the first message.
  virtual void Rewind() = 0;
  virtual MessageEncoding encoding() const = 0;
  virtual RecordingFormat format() const = 0;
};

// Every topic counted by reading each message, for a recording whose index (or summary) is missing: `next`
// reads the next message of any topic and gives the type of its topic, false at the end. Damage after the
// first message ends the count with a warning (the frames before it are still read); damage at the first is
// its InputError.
std::vector<RecordingTopic> CountTopicsByReading(
    const std::function<bool(RecordedMessage* message, std::string* type)>& next);

// Whether `path` is a recording: a .bag or .mcap file, a .db3 file, or a folder holding metadata.yaml and .db3 files.
bool IsRecording(const std::string& path);
// Opens a recording (IsRecording). Throws InputError naming the file when it is not one vmap can read: also
// when it, or a file of its folder, is not a regular file (a FIFO would block, a device never ends) or is a
// symbolic link leading out of the folder. Every reader keeps to `limits` (recording_limits.h) whatever the
// recording announces, and throws InputError naming the file and the offset past them.
std::unique_ptr<RecordingReader> OpenRecording(const std::string& path, const RecordingLimits& limits = {});

// Readers of each container (ros1_bag_reader.cc, rosbag2_sqlite_reader.cc, mcap_reader.cc).
std::unique_ptr<RecordingReader> OpenRos1Bag(const std::string& path, const RecordingLimits& limits = {});
std::unique_ptr<RecordingReader> OpenRosbag2(const std::string& path, const RecordingLimits& limits = {});
std::unique_ptr<RecordingReader> OpenMcap(const std::string& path, const RecordingLimits& limits = {});
// The .mcap file `name` of the rosbag2 folder `folder` (written with the MCAP storage plugin).
std::unique_ptr<RecordingReader> OpenMcapInFolder(const std::filesystem::path& folder, const std::string& name,
                                                  const RecordingLimits& limits = {});

// "sensor_msgs/msg/Image" -> "sensor_msgs/Image": one name for a type in ROS 1 and ROS 2.
std::string NormalizedTypeName(const std::string& type);

}  // namespace vmap
