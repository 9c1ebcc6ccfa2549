// ROS 1 bags, format 2.0: "#ROSBAG V2.0\n", then records of [uint32 header length][header: fields of
// uint32 length + "name=value"][uint32 data length][data]. Chunk records (op 0x05) hold, compressed with
// none, bz2 or lz4, the connection records (op 0x07: which topic and type a connection id is) and message
// records (op 0x02: connection id, receive time, serialized message). The index at the end is optional (a
// bag still being recorded has none), so the reader walks the records in order, one chunk in memory at a time.
//
// Why not Debian's librosbag-storage: it needs roscpp_serialization, roscpp_traits, rostime, cpp_common,
// console_bridge, Boost and the message headers of every type it reads, and its View sorts all messages'
// index entries in memory before the first one is read. This reader is one file over libbz2 and liblz4, reads
// the bag in one forward pass (memory: one chunk), and gives the frames before a damaged record.

#include <algorithm>
#include <map>
#include <utility>

#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/binary_file.h"
#include "vmap/sources/chunk_decompression.h"
#include "vmap/sources/indexed_file_reader.h"
#include "vmap/sources/recording_reader.h"

namespace vmap {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr size_t kMagicSize = sizeof(kMagic) - 1;
constexpr uint8_t kOpMessage = 0x02, kOpChunk = 0x05, kOpConnection = 0x07;
// A record header is a handful of short fields. Larger values are damage.
constexpr uint32_t kMaxHeaderSize = 1 << 20;

struct Connection {
  std::string topic;
  std::string type;
};

// The fields of a record header, each a view into the header's bytes.
class RecordHeader {
 public:
  // Returns "" or what is wrong with the header.
  std::string Parse(const uint8_t* data, size_t size) {
    fields_.clear();
    size_t at = 0;
    while (at < size) {
      if (size - at < 4) return "a header field's length is cut off";
      const uint32_t length = LoadU32(data + at);
      at += 4;
      if (length > size - at) return "a header field's length " + std::to_string(length) + " runs past the header";
      const char* field = reinterpret_cast<const char*>(data + at);
      size_t equals = 0;
      while (equals < length && field[equals] != '=') ++equals;
      if (equals == length) return "a header field has no '='";
      fields_.emplace(std::string(field, equals), std::string(field + equals + 1, length - equals - 1));
      at += length;
    }
    return "";
  }
  const std::string* Find(const std::string& name) const {
    const auto it = fields_.find(name);
    return it == fields_.end() ? nullptr : &it->second;
  }
  uint8_t op() const { return Number<uint8_t>("op", 1); }
  template <typename T>
  T Number(const std::string& name, size_t bytes) const {
    const std::string* value = Find(name);
    if (!value || value->size() != bytes) return T{};
    const auto* b = reinterpret_cast<const uint8_t*>(value->data());
    if (bytes == 1) return static_cast<T>(b[0]);
    if (bytes == 4) return static_cast<T>(LoadU32(b));
    return static_cast<T>(LoadU64(b));
  }

 private:
  std::map<std::string, std::string> fields_;
};

class Ros1BagReader : public IndexedFileReader {
 public:
  Ros1BagReader(const std::string& path, const RecordingLimits& limits)
      : file_(path), limits_(limits), budget_(limits, file_.size()) {
    uint8_t magic[kMagicSize];
    if (file_.size() < kMagicSize) file_.Damaged(0, "it is not a ROS bag (too short)");
    file_.Read(0, kMagicSize, magic, "the bag's version line");
    if (std::string(reinterpret_cast<char*>(magic), kMagicSize) != kMagic) {
      throw InputError("'" + path +
                       "' is not a ROS 1 bag of format 2.0 (it does not start with '#ROSBAG V2.0'); "
                       "migrate older bags with `rosbag fix`, or give a ROS 2 recording as its folder or .mcap file");
    }
    Rewind();
  }

  MessageEncoding encoding() const override { return MessageEncoding::kRos1; }
  RecordingFormat format() const override { return RecordingFormat::kRos1Bag; }

  void Rewind() override {
    position_ = kMagicSize;
    chunk_.clear();
    chunk_position_ = 0;
    budget_.Reset();
  }

 private:
  // The topics as the bag's index at its end counts them (connection and chunk info records), without reading
  // the chunks; false when the bag has no index (still being recorded, or cut short) or it does not add up.
  // First and last times are those of the chunks holding the topic's messages.
  bool TopicsFromIndex(std::vector<RecordingTopic>* topics) override {
    try {
      uint8_t length[4];
      file_.Read(kMagicSize, 4, length, "the bag header");
      const uint32_t header_size = LoadU32(length);
      if (header_size > kMaxHeaderSize) return false;
      file_.Read(kMagicSize + 4, header_size, &header_bytes_, "the bag header");
      RecordHeader bag_header;
      if (!bag_header.Parse(header_bytes_.data(), header_bytes_.size()).empty() || bag_header.op() != 0x03)
        return false;
      uint64_t position = bag_header.Number<uint64_t>("index_pos", 8);
      const uint32_t chunk_count = bag_header.Number<uint32_t>("chunk_count", 4);
      if (position <= kMagicSize || position >= file_.size()) return false;
      std::map<uint32_t, RecordingTopic> by_connection;
      uint32_t chunks = 0;
      while (position < file_.size()) {
        file_.Read(position, 4, length, "an index record");
        const uint32_t size = LoadU32(length);
        if (size > kMaxHeaderSize) return false;
        file_.Read(position + 4, size, &header_bytes_, "an index record");
        if (!header_.Parse(header_bytes_.data(), header_bytes_.size()).empty()) return false;
        file_.Read(position + 4 + size, 4, length, "an index record");
        const uint32_t data_size = LoadU32(length);
        file_.Read(position + 8 + size, data_size, &record_data_, "an index record");
        position += 8 + size + uint64_t{data_size};
        const uint32_t id = header_.Number<uint32_t>("conn", 4);
        if (header_.op() == kOpConnection) {
          RecordHeader connection_header;
          const std::string* topic = header_.Find("topic");
          if (!topic || !connection_header.Parse(record_data_.data(), record_data_.size()).empty() ||
              !connection_header.Find("type")) {
            return false;
          }
          by_connection[id].name = *topic;
          by_connection[id].type = *connection_header.Find("type");
        } else if (header_.op() == 0x06) {  // chunk info: (connection, count) pairs of one chunk
          ++chunks;
          const auto nanoseconds = [](uint64_t time) {
            return static_cast<int64_t>(time & 0xffffffffu) * 1000000000 + static_cast<int64_t>(time >> 32);
          };
          const int64_t start = nanoseconds(header_.Number<uint64_t>("start_time", 8));
          const int64_t end = nanoseconds(header_.Number<uint64_t>("end_time", 8));
          for (size_t at = 0; at + 8 <= record_data_.size(); at += 8) {
            RecordingTopic& topic = by_connection[LoadU32(record_data_.data() + at)];
            if (topic.message_count == 0 || start < topic.first_time_ns) topic.first_time_ns = start;
            topic.last_time_ns = std::max(topic.last_time_ns, end);
            topic.message_count += LoadU32(record_data_.data() + at + 4);
          }
        }
      }
      if (chunks != chunk_count) return false;
      std::map<std::string, RecordingTopic> by_topic;  // several connections may share a topic
      for (const auto& [id, connection] : by_connection) {
        if (connection.name.empty()) return false;  // counted messages of a connection the index does not name
        RecordingTopic& topic = by_topic[connection.name];
        if (topic.message_count == 0)
          topic = connection;
        else {
          topic.first_time_ns = std::min(topic.first_time_ns, connection.first_time_ns);
          topic.last_time_ns = std::max(topic.last_time_ns, connection.last_time_ns);
          topic.message_count += connection.message_count;
        }
      }
      topics->clear();
      for (auto& [name, topic] : by_topic) topics->push_back(std::move(topic));
      return true;
    } catch (const InputError&) {
      return false;  // a damaged index: the records themselves are counted
    }
  }

  // The next message on `topics` (nullptr: every message, its data left out: a count).
  bool NextMessage(const std::set<std::string>* topics, RecordedMessage* message) override {
    for (;;) {
      if (chunk_position_ < chunk_.size()) {
        if (NextInChunk(topics, message)) return true;
        continue;
      }
      chunk_.clear();
      chunk_position_ = 0;
      if (position_ >= file_.size()) return false;
      if (NextInFile(topics, message)) return true;
    }
  }

  // One record of the file; true when it is a wanted message.
  bool NextInFile(const std::set<std::string>* topics, RecordedMessage* message) {
    const uint64_t offset = position_;
    if (const std::string over = budget_.CountRecord(); !over.empty()) file_.OverLimit(offset, over);
    uint8_t length[4];
    file_.Read(offset, 4, length, "a record's header length");
    const uint32_t header_size = LoadU32(length);
    if (header_size > kMaxHeaderSize) {
      file_.Damaged(offset, "a record header of " + std::to_string(header_size) + " bytes");
    }
    file_.Read(offset + 4, header_size, &header_bytes_, "a record header");
    file_.Read(offset + 4 + header_size, 4, length, "a record's data length");
    const uint32_t data_size = LoadU32(length);
    const uint64_t data_offset = offset + 8 + header_size;
    if (data_size > file_.size() - std::min(file_.size(), data_offset)) {
      file_.Damaged(offset, "a record announces " + std::to_string(data_size) + " bytes of data but the file ends at " +
                                std::to_string(file_.size()));
    }
    position_ = data_offset + data_size;
    const std::string problem = header_.Parse(header_bytes_.data(), header_bytes_.size());
    if (!problem.empty()) file_.Damaged(offset, problem);
    const uint8_t op = header_.op();
    if (op == kOpChunk) {
      const std::string* compression = header_.Find("compression");
      const uint32_t size = header_.Number<uint32_t>("size", 4);
      if (!compression) file_.Damaged(offset, "a chunk without a compression field");
      const uint64_t stored = *compression == "none" ? data_size : size;
      if (stored > limits_.max_chunk_bytes) {
        file_.OverLimit(offset, "a chunk announces " + std::to_string(stored) + " bytes, more than the " +
                                    std::to_string(limits_.max_chunk_bytes >> 20) +
                                    " MiB a chunk of the largest frames needs");
      }
      chunk_offset_ = offset;
      if (*compression == "none") {
        file_.Read(data_offset, data_size, &chunk_, "a chunk");
      } else {
        if (const std::string over = budget_.Spend(size); !over.empty()) file_.OverLimit(offset, "a chunk: " + over);
        file_.Read(data_offset, data_size, &compressed_, "a chunk");
        chunk_.resize(size);
        const std::string failed =
            DecompressChunk(*compression, compressed_.data(), compressed_.size(), chunk_.data(), chunk_.size());
        if (!failed.empty()) {
          chunk_.clear();
          file_.Damaged(offset, "a chunk: " + failed);
        }
      }
      chunk_position_ = 0;
      return false;
    }
    if (op != kOpConnection && op != kOpMessage) return false;  // bag header, index and chunk info records
    if (data_size > limits_.max_message_bytes) {
      file_.OverLimit(offset, "a record of " + std::to_string(data_size) +
                                  " bytes, more than a message of the largest "
                                  "frames needs");
    }
    file_.Read(data_offset, data_size, &record_data_, "a record");
    return Handle(op, record_data_.data(), record_data_.size(), offset, topics, message);
  }

  // One record of the chunk in memory.
  bool NextInChunk(const std::set<std::string>* topics, RecordedMessage* message) {
    const uint8_t* base = chunk_.data();
    const size_t size = chunk_.size();
    size_t at = chunk_position_;
    if (const std::string over = budget_.CountRecord(); !over.empty()) {
      chunk_position_ = size;
      file_.OverLimit(chunk_offset_, "in the chunk there, at byte " + std::to_string(at) + " of it: " + over);
    }
    const auto damaged = [&](const std::string& problem) {
      chunk_position_ = size;
      file_.Damaged(chunk_offset_, "in the chunk there, at byte " + std::to_string(at) + " of it: " + problem);
    };
    if (size - at < 4) damaged("a record's header length is cut off");
    const uint32_t header_size = LoadU32(base + at);
    if (header_size > size - at - 4) damaged("a record header runs past the chunk");
    const std::string problem = header_.Parse(base + at + 4, header_size);
    if (!problem.empty()) damaged(problem);
    const size_t length_at = at + 4 + header_size;
    if (size - length_at < 4) damaged("a record's data length is cut off");
    const uint32_t data_size = LoadU32(base + length_at);
    if (data_size > size - length_at - 4) damaged("a record's data runs past the chunk");
    chunk_position_ = length_at + 4 + data_size;
    return Handle(header_.op(), base + length_at + 4, data_size, chunk_offset_, topics, message);
  }

  bool Handle(uint8_t op, const uint8_t* data, size_t size, uint64_t offset, const std::set<std::string>* topics,
              RecordedMessage* message) {
    const uint32_t id = header_.Number<uint32_t>("conn", 4);
    if (op == kOpConnection) {
      // The data is the connection header, fields as in a record header: topic, type, md5sum, definition.
      const std::string* topic = header_.Find("topic");
      RecordHeader connection_header;
      if (!topic || !connection_header.Parse(data, size).empty() || !connection_header.Find("type")) {
        file_.Damaged(offset, "a connection record without its topic or type");
      }
      connections_[id] = {*topic, *connection_header.Find("type")};
      return false;
    }
    const auto connection = connections_.find(id);
    if (connection == connections_.end()) {
      file_.Damaged(offset, "a message on connection " + std::to_string(id) + ", which no record before it defines");
    }
    const std::string& topic = connection->second.topic;
    if (topics && !topics->empty() && !topics->count(topic)) return false;
    message->topic = topic;
    message->type = connection->second.type;
    const uint64_t time = header_.Number<uint64_t>("time", 8);  // uint32 seconds, then uint32 nanoseconds
    message->log_time_ns = static_cast<int64_t>(time & 0xffffffffu) * 1000000000 + static_cast<int64_t>(time >> 32);
    message->offset = offset;
    if (topics) message->data.assign(data, data + size);
    return true;
  }

  BinaryFile file_;
  RecordingLimits limits_;
  PassBudget budget_;           // of this pass through the bag
  uint64_t position_ = 0;       // the next record of the file
  std::vector<uint8_t> chunk_;  // the current chunk, decompressed
  size_t chunk_position_ = 0;
  uint64_t chunk_offset_ = 0;
  std::vector<uint8_t> header_bytes_, record_data_, compressed_;
  RecordHeader header_;
  std::map<uint32_t, Connection> connections_;
};

}  // namespace

std::unique_ptr<RecordingReader> OpenRos1Bag(const std::string& path, const RecordingLimits& limits) {
  return std::make_unique<Ros1BagReader>(path, limits);
}

}  // namespace vmap
