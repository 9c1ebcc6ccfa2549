// MCAP files with ROS 2 messages (CDR): magic "\x89MCAP0\r\n", then records of [uint8 opcode][uint64 length]
// [content] up to the Data End record. Schema (0x03) and Channel (0x04) records say which topic and type a
// channel id is; Message records (0x05) hold channel id, sequence, log and publish time, and the data;
// Chunk records (0x06) hold such records, uncompressed, zstd or lz4 (frame format). The summary at the end is
// optional (a recording cut short has none), so the reader walks the data section in order, one chunk in
// memory at a time. Strings are a uint32 length and bytes; integers little-endian.

#include <algorithm>
#include <map>

#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/binary_file.h"
#include "vmap/sources/chunk_decompression.h"
#include "vmap/sources/indexed_file_reader.h"
#include "vmap/sources/recording_reader.h"

namespace vmap {
namespace {

constexpr uint8_t kMcapMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint8_t kMcapFooter = 0x02, kMcapSchema = 0x03, kMcapChannel = 0x04, kMcapMessage = 0x05, kMcapChunk = 0x06,
                  kMcapDataEnd = 0x0F;

struct Channel {
  std::string topic;
  uint16_t schema = 0;
  std::string encoding;
};

// Reads the fields of one record's content; false once a field would run past it.
class Fields {
 public:
  Fields(const uint8_t* data, uint64_t size) : data_(data), size_(size) {}
  bool U16(uint16_t* v) {
    return Fixed(2, [&](const uint8_t* b) { *v = LoadU16(b); });
  }
  bool U32(uint32_t* v) {
    return Fixed(4, [&](const uint8_t* b) { *v = LoadU32(b); });
  }
  bool U64(uint64_t* v) {
    return Fixed(8, [&](const uint8_t* b) { *v = LoadU64(b); });
  }
  bool String(std::string* v) {
    uint32_t length = 0;
    if (!U32(&length) || length > size_ - at_) return false;
    v->assign(reinterpret_cast<const char*>(data_ + at_), length);
    at_ += length;
    return true;
  }
  const uint8_t* rest(uint64_t* size) const {
    *size = size_ - at_;
    return data_ + at_;
  }

 private:
  template <typename Load>
  bool Fixed(uint64_t n, Load load) {
    if (n > size_ - at_) return false;
    load(data_ + at_);
    at_ += n;
    return true;
  }
  const uint8_t* data_;
  uint64_t size_;
  uint64_t at_ = 0;
};

class McapReader : public IndexedFileReader {
 public:
  McapReader(BinaryFile file, const RecordingLimits& limits)
      : file_(std::move(file)), limits_(limits), budget_(limits, file_.size()) {
    const std::string& path = file_.path();
    uint8_t magic[8] = {};
    if (file_.size() < 8) file_.Damaged(0, "it is not an MCAP file (too short)");
    file_.Read(0, 8, magic, "the magic bytes");
    if (!std::equal(magic, magic + 8, kMcapMagic)) {
      throw InputError("'" + path + "' is not an MCAP file of version 0 (its magic bytes differ)");
    }
    Rewind();
  }

  MessageEncoding encoding() const override { return MessageEncoding::kCdr; }
  RecordingFormat format() const override { return RecordingFormat::kMcap; }

  void Rewind() override {
    position_ = 8;
    ended_ = false;
    chunk_.clear();
    chunk_position_ = 0;
    budget_.Reset();
  }

 private:
  // The topics as the summary section counts them (Statistics: messages per channel; Chunk Index: which
  // channels each chunk holds, and its first and last log time), without reading the chunks; false when the
  // file has no summary (a recording cut short) or it lacks those records.
  bool TopicsFromIndex(std::vector<RecordingTopic>* topics) override {
    constexpr uint64_t kFooterSize = 9 + 20;
    try {
      if (file_.size() < 8 + kFooterSize + 8) return false;
      const uint64_t footer_offset = file_.size() - 8 - kFooterSize;
      file_.Read(footer_offset, kFooterSize, &record_, "the footer");
      if (record_[0] != kMcapFooter) return false;
      uint64_t position = LoadU64(record_.data() + 9);
      if (position == 0 || position >= footer_offset) return false;
      std::map<uint16_t, Channel> channels;
      std::map<uint16_t, std::string> schemas;
      std::map<uint16_t, RecordingTopic> by_channel;
      bool statistics = false;
      uint64_t file_start = 0, file_end = 0;  // of all messages: the times of channels no chunk index names
      while (position < footer_offset) {
        uint8_t head[9];
        file_.Read(position, 9, head, "a summary record");
        const uint64_t length = LoadU64(head + 1);
        if (length > footer_offset - position - 9) return false;
        file_.Read(position + 9, length, &record_, "a summary record");
        position += 9 + length;
        Fields fields(record_.data(), record_.size());
        if (head[0] == kMcapSchema) {
          uint16_t id = 0;
          if (!fields.U16(&id) || !fields.String(&schemas[id])) return false;
        } else if (head[0] == kMcapChannel) {
          uint16_t id = 0;
          Channel channel;
          if (!fields.U16(&id) || !fields.U16(&channel.schema) || !fields.String(&channel.topic)) return false;
          channels[id] = channel;
        } else if (head[0] == 0x0B) {  // Statistics
          uint64_t skip64 = 0;
          uint32_t skip32 = 0, map_size = 0;
          uint16_t skip16 = 0;
          if (!fields.U64(&skip64) || !fields.U16(&skip16) || !fields.U32(&skip32) || !fields.U32(&skip32) ||
              !fields.U32(&skip32) || !fields.U32(&skip32) || !fields.U64(&file_start) || !fields.U64(&file_end) ||
              !fields.U32(&map_size)) {
            return false;
          }
          for (uint32_t read = 0; read + 10 <= map_size; read += 10) {
            uint16_t id = 0;
            uint64_t count = 0;
            if (!fields.U16(&id) || !fields.U64(&count)) return false;
            by_channel[id].message_count = static_cast<long>(count);
          }
          statistics = true;
        } else if (head[0] == 0x08) {  // Chunk Index
          uint64_t start = 0, end = 0, skip = 0;
          uint32_t map_size = 0;
          if (!fields.U64(&start) || !fields.U64(&end) || !fields.U64(&skip) || !fields.U64(&skip) ||
              !fields.U32(&map_size)) {
            return false;
          }
          for (uint32_t read = 0; read + 10 <= map_size; read += 10) {
            uint16_t id = 0;
            if (!fields.U16(&id) || !fields.U64(&skip)) return false;
            RecordingTopic& topic = by_channel[id];
            if (topic.last_time_ns == 0 || static_cast<int64_t>(start) < topic.first_time_ns) {
              topic.first_time_ns = static_cast<int64_t>(start);
            }
            topic.last_time_ns = std::max(topic.last_time_ns, static_cast<int64_t>(end));
          }
        }
      }
      if (!statistics) return false;
      std::map<std::string, RecordingTopic> by_topic;
      for (auto& [id, counted] : by_channel) {
        const auto channel = channels.find(id);
        if (channel == channels.end()) return false;
        if (counted.last_time_ns == 0) {
          counted.first_time_ns = static_cast<int64_t>(file_start);
          counted.last_time_ns = static_cast<int64_t>(file_end);
        }
        RecordingTopic& topic = by_topic[channel->second.topic];
        const auto schema = schemas.find(channel->second.schema);
        if (topic.message_count == 0) {
          topic.first_time_ns = counted.first_time_ns;
        } else {
          topic.first_time_ns = std::min(topic.first_time_ns, counted.first_time_ns);
        }
        topic.name = channel->second.topic;
        topic.type = schema == schemas.end() ? "" : schema->second;
        topic.last_time_ns = std::max(topic.last_time_ns, counted.last_time_ns);
        topic.message_count += counted.message_count;
      }
      topics->clear();
      for (auto& [name, topic] : by_topic) {
        if (topic.message_count > 0) topics->push_back(std::move(topic));
      }
      return true;
    } catch (const InputError&) {
      return false;  // a damaged summary: the records themselves are counted
    }
  }

  bool NextMessage(const std::set<std::string>* topics, RecordedMessage* message) override {
    for (;;) {
      if (chunk_position_ < chunk_.size()) {
        const uint64_t at = chunk_position_;
        const uint64_t left = chunk_.size() - at;
        if (const std::string over = budget_.CountRecord(); !over.empty()) {
          chunk_position_ = chunk_.size();
          file_.OverLimit(chunk_offset_, "in the chunk there, at byte " + std::to_string(at) + " of it: " + over);
        }
        if (left < 9) ChunkDamaged(at, "a record's opcode and length are cut off");
        const uint64_t length = LoadU64(chunk_.data() + at + 1);
        if (length > left - 9) ChunkDamaged(at, "a record runs past the chunk");
        chunk_position_ = at + 9 + length;
        if (Handle(chunk_[at], chunk_.data() + at + 9, length, chunk_offset_, topics, message)) return true;
        continue;
      }
      chunk_.clear();
      chunk_position_ = 0;
      if (ended_ || position_ >= file_.size()) return false;
      const uint64_t offset = position_;
      if (const std::string over = budget_.CountRecord(); !over.empty()) file_.OverLimit(offset, over);
      uint8_t head[9];
      file_.Read(offset, 9, head, "a record's opcode and length");
      const uint64_t length = LoadU64(head + 1);
      if (length > file_.size() - offset - 9) {
        file_.Damaged(offset, "a record announces " + std::to_string(length) + " bytes but the file ends at " +
                                  std::to_string(file_.size()));
      }
      position_ = offset + 9 + length;
      const uint8_t op = head[0];
      if (op == kMcapDataEnd || op == kMcapFooter) {
        ended_ = true;  // the summary that follows repeats the schemas and channels
        continue;
      }
      if (op != kMcapSchema && op != kMcapChannel && op != kMcapMessage && op != kMcapChunk) continue;
      if (length > (op == kMcapChunk ? limits_.max_chunk_bytes : limits_.max_message_bytes)) {
        file_.OverLimit(offset, "a record of " + std::to_string(length) +
                                    " bytes, more than one of the largest frames "
                                    "needs");
      }
      file_.Read(offset + 9, length, &record_, "a record");
      if (op == kMcapChunk) {
        ReadChunk(offset);
        continue;
      }
      if (Handle(op, record_.data(), record_.size(), offset, topics, message)) return true;
    }
  }

  void ReadChunk(uint64_t offset) {
    Fields fields(record_.data(), record_.size());
    uint64_t start = 0, end = 0, size = 0, records_size = 0;
    uint32_t crc = 0;
    std::string compression;
    if (!fields.U64(&start) || !fields.U64(&end) || !fields.U64(&size) || !fields.U32(&crc) ||
        !fields.String(&compression) || !fields.U64(&records_size)) {
      file_.Damaged(offset, "a chunk record's fields are cut off");
    }
    uint64_t left = 0;
    const uint8_t* records = fields.rest(&left);
    if (records_size > left) file_.Damaged(offset, "a chunk's records run past it");
    if (size > limits_.max_chunk_bytes) {
      file_.OverLimit(offset, "a chunk announces " + std::to_string(size) + " bytes, more than the " +
                                  std::to_string(limits_.max_chunk_bytes >> 20) +
                                  " MiB a chunk of the largest frames needs");
    }
    chunk_offset_ = offset;
    if (compression.empty()) {
      if (size != records_size) file_.Damaged(offset, "an uncompressed chunk whose sizes differ");
      chunk_.assign(records, records + records_size);
    } else {
      if (const std::string over = budget_.Spend(size); !over.empty()) file_.OverLimit(offset, "a chunk: " + over);
      chunk_.resize(size);
      const std::string failed = DecompressChunk(compression, records, records_size, chunk_.data(), size);
      if (!failed.empty()) {
        chunk_.clear();
        file_.Damaged(offset, "a chunk: " + failed);
      }
    }
    chunk_position_ = 0;
  }

  [[noreturn]] void ChunkDamaged(uint64_t at, const std::string& problem) {
    chunk_position_ = chunk_.size();
    file_.Damaged(chunk_offset_, "in the chunk there, at byte " + std::to_string(at) + " of it: " + problem);
  }

  bool Handle(uint8_t op, const uint8_t* data, uint64_t size, uint64_t offset, const std::set<std::string>* topics,
              RecordedMessage* message) {
    Fields fields(data, size);
    if (op == kMcapSchema) {
      uint16_t id = 0;
      std::string name;
      if (!fields.U16(&id) || !fields.String(&name)) file_.Damaged(offset, "a schema record is cut off");
      schemas_[id] = name;
      return false;
    }
    if (op == kMcapChannel) {
      uint16_t id = 0;
      Channel channel;
      if (!fields.U16(&id) || !fields.U16(&channel.schema) || !fields.String(&channel.topic) ||
          !fields.String(&channel.encoding)) {
        file_.Damaged(offset, "a channel record is cut off");
      }
      channels_[id] = channel;
      return false;
    }
    if (op != kMcapMessage) return false;
    uint16_t id = 0;
    uint32_t sequence = 0;
    uint64_t log_time = 0, publish_time = 0;
    if (!fields.U16(&id) || !fields.U32(&sequence) || !fields.U64(&log_time) || !fields.U64(&publish_time)) {
      file_.Damaged(offset, "a message record is cut off");
    }
    const auto channel = channels_.find(id);
    if (channel == channels_.end()) {
      file_.Damaged(offset, "a message on channel " + std::to_string(id) + ", which no record before it defines");
    }
    const std::string& topic = channel->second.topic;
    if (topics && !topics->empty() && !topics->count(topic)) return false;
    const auto schema = schemas_.find(channel->second.schema);
    message->type = schema == schemas_.end() ? "" : schema->second;
    if (topics && channel->second.encoding != "cdr") {
      throw InputError("MCAP file '" + file_.path() + "': topic " + topic + " is encoded as '" +
                       channel->second.encoding + "'; vmap reads ROS 2 messages encoded as cdr");
    }
    message->topic = topic;
    message->log_time_ns = static_cast<int64_t>(log_time);
    message->offset = offset;
    if (topics) {
      uint64_t left = 0;
      const uint8_t* payload = fields.rest(&left);
      message->data.assign(payload, payload + left);
    }
    return true;
  }

  BinaryFile file_;
  RecordingLimits limits_;
  PassBudget budget_;  // of this pass through the file
  uint64_t position_ = 8;
  bool ended_ = false;
  std::vector<uint8_t> record_, chunk_;
  uint64_t chunk_position_ = 0;
  uint64_t chunk_offset_ = 0;
  std::map<uint16_t, std::string> schemas_;
  std::map<uint16_t, Channel> channels_;
};

}  // namespace

std::unique_ptr<RecordingReader> OpenMcap(const std::string& path, const RecordingLimits& limits) {
  return std::make_unique<McapReader>(BinaryFile(path), limits);
}

std::unique_ptr<RecordingReader> OpenMcapInFolder(const std::filesystem::path& folder, const std::string& name,
                                                  const RecordingLimits& limits) {
  return std::make_unique<McapReader>(BinaryFile(folder, name), limits);
}

}  // namespace vmap
