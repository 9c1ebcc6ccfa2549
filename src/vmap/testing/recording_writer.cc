#include "vmap/testing/recording_writer.h"

#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

#include "vmap/testing/run_vmap.h"

namespace vmap::testing {
namespace {
namespace fs = std::filesystem;

// The inverse of sources/message_buffer.h, little-endian only.
class MessageWriter {
 public:
  explicit MessageWriter(MessageEncoding encoding) : cdr_(encoding == MessageEncoding::kCdr) {
    if (cdr_) bytes_ = {0, 1, 0, 0};
  }
  void U8(uint8_t v) { bytes_.push_back(v); }
  void U32(uint32_t v) {
    Align(4);
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void F64(double v) {
    Align(8);
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<uint8_t>(bits >> (8 * i)));
  }
  void String(const std::string& s) {
    U32(static_cast<uint32_t>(s.size() + (cdr_ ? 1 : 0)));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    if (cdr_) bytes_.push_back(0);
  }
  void Bytes(const uint8_t* data, size_t size) {
    U32(static_cast<uint32_t>(size));
    bytes_.insert(bytes_.end(), data, data + size);
  }
  void Header(double stamp, const std::string& frame_id) {
    if (!cdr_) U32(7);  // seq
    const double seconds = std::floor(stamp);
    U32(static_cast<uint32_t>(seconds));
    U32(static_cast<uint32_t>(std::lround((stamp - seconds) * 1e9)));
    String(frame_id);
  }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  void Align(size_t n) {
    if (!cdr_) return;
    while ((bytes_.size() - 4) % n != 0) bytes_.push_back(0);
  }
  bool cdr_;
  std::vector<uint8_t> bytes_;
};

std::string Ros2Type(const std::string& type) {
  const size_t slash = type.find('/');
  return type.substr(0, slash) + "/msg/" + type.substr(slash + 1);
}

void Put16(std::string& out, uint16_t v) { out.append(reinterpret_cast<const char*>(&v), 2); }
void Put32(std::string& out, uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }
void Put64(std::string& out, uint64_t v) { out.append(reinterpret_cast<const char*>(&v), 8); }
void PutString(std::string& out, const std::string& s) {
  Put32(out, static_cast<uint32_t>(s.size()));
  out += s;
}
void PutRecord(std::string& out, uint8_t op, const std::string& content) {
  out.push_back(static_cast<char>(op));
  Put64(out, content.size());
  out += content;
}

std::string Compress(const std::string& compression, const std::string& data) {
  if (compression == "none") return data;
  std::string out;
  if (compression == "zstd") {
    out.resize(ZSTD_compressBound(data.size()));
    out.resize(ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 3));
  } else {
    out.resize(LZ4F_compressFrameBound(data.size(), nullptr));
    out.resize(LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), nullptr));
  }
  return out;
}

void Check(int status, sqlite3* db, const char* what) {
  if (status != SQLITE_OK && status != SQLITE_DONE) {
    throw std::runtime_error(std::string(what) + ": " + sqlite3_errmsg(db));
  }
}

}  // namespace

std::vector<uint8_t> SerializeImage(MessageEncoding encoding, double stamp, const std::string& frame_id,
                                    const cv::Mat& pixels, const std::string& image_encoding, int padding) {
  MessageWriter writer(encoding);
  writer.Header(stamp, frame_id);
  writer.U32(static_cast<uint32_t>(pixels.rows));
  writer.U32(static_cast<uint32_t>(pixels.cols));
  writer.String(image_encoding);
  writer.U8(0);
  const size_t row = pixels.cols * pixels.elemSize();
  writer.U32(static_cast<uint32_t>(row + padding));
  std::vector<uint8_t> data;
  for (int y = 0; y < pixels.rows; ++y) {
    data.insert(data.end(), pixels.ptr<uint8_t>(y), pixels.ptr<uint8_t>(y) + row);
    data.insert(data.end(), padding, 0xAB);
  }
  writer.Bytes(data.data(), data.size());
  return writer.Take();
}

std::vector<uint8_t> SerializeCompressedImage(MessageEncoding encoding, double stamp, const std::string& format,
                                              const std::vector<uint8_t>& bytes) {
  MessageWriter writer(encoding);
  writer.Header(stamp, "camera");
  writer.String(format);
  writer.Bytes(bytes.data(), bytes.size());
  return writer.Take();
}

std::vector<uint8_t> SerializeCameraInfo(MessageEncoding encoding, double stamp, const std::string& frame_id,
                                         cv::Size size, const std::string& model, const std::vector<double>& d,
                                         const cv::Matx33d& k) {
  MessageWriter writer(encoding);
  writer.Header(stamp, frame_id);
  writer.U32(static_cast<uint32_t>(size.height));
  writer.U32(static_cast<uint32_t>(size.width));
  writer.String(model);
  writer.U32(static_cast<uint32_t>(d.size()));
  for (double v : d) writer.F64(v);
  for (int i = 0; i < 9; ++i) writer.F64(k.val[i]);
  const double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (double v : r) writer.F64(v);
  const double p[12] = {k(0, 0), 0, k(0, 2), 0, 0, k(1, 1), k(1, 2), 0, 0, 0, 1, 0};
  for (double v : p) writer.F64(v);
  for (int i = 0; i < 6; ++i) writer.U32(0);  // binning x, y; roi x, y, height, width
  writer.U8(0);                               // roi.do_rectify
  return writer.Take();
}

std::vector<uint8_t> SerializeOdometry(MessageEncoding encoding, double stamp, double x, double y, double yaw) {
  MessageWriter writer(encoding);
  writer.Header(stamp, "odom");
  writer.String("base_link");
  for (double v : {x, y, 0.0, 0.0, 0.0, std::sin(0.5 * yaw), std::cos(0.5 * yaw)}) writer.F64(v);
  for (int i = 0; i < 36 + 6 + 36; ++i) writer.F64(0.0);  // pose covariance, twist, twist covariance
  return writer.Take();
}

void WriteMcap(const std::string& path, const std::vector<TestMessage>& messages, const std::string& compression,
               int per_chunk, bool summary) {
  std::string file("\x89MCAP0\r\n", 8);
  std::string header;
  PutString(header, "ros2");
  PutString(header, "vmap-test");
  PutRecord(file, 0x01, header);
  std::map<std::string, uint16_t> channels;  // a channel per topic and type, as a publisher per type would have
  std::string pending, chunk_indexes, definitions;
  std::set<uint16_t> in_chunk_channels;
  uint32_t chunk_count = 0;
  std::map<uint16_t, uint64_t> counts;
  int64_t first_time = messages.empty() ? 0 : messages.front().log_time_ns, last_time = first_time;
  int in_chunk = 0;
  int64_t start = 0, end = 0;
  const auto flush = [&] {
    if (pending.empty()) return;
    if (compression.empty()) {
      file += pending;
    } else {
      const std::string stored = Compress(compression, pending);
      std::string chunk;
      Put64(chunk, static_cast<uint64_t>(start));
      Put64(chunk, static_cast<uint64_t>(end));
      Put64(chunk, pending.size());
      Put32(chunk, 0);  // no CRC: optional in MCAP
      PutString(chunk, compression == "none" ? "" : compression);
      Put64(chunk, stored.size());
      chunk += stored;
      std::string index;  // the chunk's Chunk Index record, for the summary
      Put64(index, static_cast<uint64_t>(start));
      Put64(index, static_cast<uint64_t>(end));
      Put64(index, file.size());
      Put64(index, 9 + chunk.size());
      Put32(index, static_cast<uint32_t>(10 * in_chunk_channels.size()));
      for (uint16_t id : in_chunk_channels) {
        Put16(index, id);
        Put64(index, 0);  // no Message Index records: vmap does not read them
      }
      Put64(index, 0);
      PutString(index, compression == "none" ? "" : compression);
      Put64(index, stored.size());
      Put64(index, pending.size());
      PutRecord(chunk_indexes, 0x08, index);
      ++chunk_count;
      PutRecord(file, 0x06, chunk);
    }
    in_chunk_channels.clear();
    pending.clear();
    in_chunk = 0;
  };
  for (const TestMessage& message : messages) {
    const std::string channel_key = message.topic + '\n' + message.type;
    auto channel = channels.find(channel_key);
    if (channel == channels.end()) {
      const auto id = static_cast<uint16_t>(channels.size() + 1);
      channel = channels.emplace(channel_key, id).first;
      std::string schema, record;
      Put16(schema, id);
      PutString(schema, Ros2Type(message.type));
      PutString(schema, "ros2msg");
      PutString(schema, "");  // the definition; vmap does not need it
      PutRecord(pending, 0x03, schema);
      PutRecord(definitions, 0x03, schema);
      Put16(record, id);
      Put16(record, id);
      PutString(record, message.topic);
      PutString(record, "cdr");
      Put32(record, 0);  // metadata: an empty map
      PutRecord(pending, 0x04, record);
      PutRecord(definitions, 0x04, record);
    }
    in_chunk_channels.insert(channel->second);
    ++counts[channel->second];
    first_time = std::min(first_time, message.log_time_ns);
    last_time = std::max(last_time, message.log_time_ns);
    if (in_chunk == 0) start = message.log_time_ns;
    end = message.log_time_ns;
    std::string record;
    Put16(record, channel->second);
    Put32(record, 0);
    Put64(record, static_cast<uint64_t>(message.log_time_ns));
    Put64(record, static_cast<uint64_t>(message.log_time_ns));
    record.append(reinterpret_cast<const char*>(message.data.data()), message.data.size());
    PutRecord(pending, 0x05, record);
    if (++in_chunk >= per_chunk) flush();
  }
  flush();
  std::string data_end;
  Put32(data_end, 0);
  PutRecord(file, 0x0F, data_end);
  const uint64_t summary_start = summary ? file.size() : 0;
  if (summary) {
    std::string statistics;
    Put64(statistics, messages.size());
    Put16(statistics, static_cast<uint16_t>(channels.size()));
    Put32(statistics, static_cast<uint32_t>(channels.size()));
    Put32(statistics, 0);  // attachments
    Put32(statistics, 0);  // metadata
    Put32(statistics, chunk_count);
    Put64(statistics, static_cast<uint64_t>(first_time));
    Put64(statistics, static_cast<uint64_t>(last_time));
    Put32(statistics, static_cast<uint32_t>(10 * counts.size()));
    for (const auto& [id, count] : counts) {
      Put16(statistics, id);
      Put64(statistics, count);
    }
    file += definitions + chunk_indexes;
    PutRecord(file, 0x0B, statistics);
  }
  std::string footer;
  Put64(footer, summary_start);
  Put64(footer, 0);
  Put32(footer, 0);
  PutRecord(file, 0x02, footer);
  file.append("\x89MCAP0\r\n", 8);
  std::ofstream(path, std::ios::binary) << file;
}

namespace {
void WriteRosbag2Database(const std::string& file, const std::vector<TestMessage>& messages, bool compress_messages) {
  sqlite3* db = nullptr;
  Check(sqlite3_open(file.c_str(), &db), db, "open");
  const std::unique_ptr<sqlite3, decltype(&sqlite3_close)> closer(db, &sqlite3_close);
  Check(sqlite3_exec(db,
                     "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
                     "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
                     "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT "
                     "NULL, data BLOB NOT NULL); BEGIN;",
                     nullptr, nullptr, nullptr),
        db, "create");
  std::map<std::string, int> topics;
  for (const TestMessage& message : messages) {
    if (topics.count(message.topic)) continue;
    const int id = static_cast<int>(topics.size() + 1);
    topics[message.topic] = id;
    sqlite3_stmt* insert = nullptr;
    Check(sqlite3_prepare_v2(db, "INSERT INTO topics VALUES (?, ?, ?, 'cdr', '')", -1, &insert, nullptr), db, "topic");
    sqlite3_bind_int(insert, 1, id);
    sqlite3_bind_text(insert, 2, message.topic.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert, 3, Ros2Type(message.type).c_str(), -1, SQLITE_TRANSIENT);
    Check(sqlite3_step(insert), db, "topic");
    sqlite3_finalize(insert);
  }
  sqlite3_stmt* insert = nullptr;
  Check(
      sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1, &insert, nullptr),
      db, "message");
  for (const TestMessage& message : messages) {
    sqlite3_bind_int(insert, 1, topics[message.topic]);
    sqlite3_bind_int64(insert, 2, message.log_time_ns);
    std::vector<uint8_t> packed;
    if (compress_messages) {
      packed.resize(ZSTD_compressBound(message.data.size()));
      packed.resize(ZSTD_compress(packed.data(), packed.size(), message.data.data(), message.data.size(), 3));
    }
    const std::vector<uint8_t>& data = compress_messages ? packed : message.data;
    sqlite3_bind_blob(insert, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    Check(sqlite3_step(insert), db, "message");
    sqlite3_reset(insert);
  }
  sqlite3_finalize(insert);
  Check(sqlite3_exec(db, "COMMIT;", nullptr, nullptr, nullptr), db, "commit");
}
}  // namespace

void WriteRosbag2(const std::string& folder, const std::vector<TestMessage>& messages, const std::string& compression) {
  if (compression != "" && compression != "message" && compression != "file") {
    throw std::invalid_argument("WriteRosbag2: compression " + compression);
  }
  fs::create_directories(folder);
  const std::string name = fs::path(folder).filename().string();
  std::ofstream(fs::path(folder) / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n  relative_file_paths:\n    - "
      << name << (compression == "file" ? "_0.db3.zstd" : "_0.db3")
      << "\n  compression_format: " << (compression.empty() ? "\"\"" : "zstd") << "\n  compression_mode: "
      << (compression.empty()     ? "\"\""
          : compression == "file" ? "FILE"
                                  : "MESSAGE")
      << "\n";
  const std::string file = (fs::path(folder) / (name + "_0.db3")).string();
  WriteRosbag2Database(file, messages, compression == "message");
  if (compression == "file") {
    std::ifstream in(file, std::ios::binary);
    const std::string plain((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string packed(ZSTD_compressBound(plain.size()), '\0');
    packed.resize(ZSTD_compress(packed.data(), packed.size(), plain.data(), plain.size(), 3));
    std::ofstream(file + ".zstd", std::ios::binary) << packed;
    fs::remove(file);
  }
}

bool WriteRos1Bag(const std::string& path, const std::vector<TestMessage>& messages, const std::string& compression,
                  std::string* why) {
  if (std::system("/usr/bin/python3 -c 'import rosbag' >/dev/null 2>&1") != 0) {
    *why = "Debian's python3-rosbag is not installed (/usr/bin/python3 cannot import rosbag)";
    return false;
  }
  // The messages, for the script: [uint32 length, bytes] of topic, type and data, and an int64 time.
  const std::string list = path + ".messages";
  {
    std::ofstream out(list, std::ios::binary);
    std::string record;
    for (const TestMessage& message : messages) {
      record.clear();
      PutString(record, message.topic);
      PutString(record, message.type);
      Put64(record, static_cast<uint64_t>(message.log_time_ns));
      PutString(record, std::string(message.data.begin(), message.data.end()));
      out << record;
    }
  }
  const std::string command = "/usr/bin/python3 " + Quote(VMAP_ROS1_BAG_WRITER) + " " + Quote(path) + " " +
                              Quote(compression) + " " + Quote(list) + " 2>&1";
  const int status = std::system(command.c_str());
  fs::remove(list);
  if (status != 0) {
    *why = "`" + command + "` failed";
    return false;
  }
  return true;
}

}  // namespace vmap::testing
