// ROS 2 bags in rosbag2's sqlite3 storage: a folder with metadata.yaml and one or more .db3 files (split
// bags: NAME_0.db3, NAME_1.db3, ... read in natural order), or one .db3 file. Each database has a `topics`
// table (id, name, type, serialization_format) and a `messages` table (topic_id, timestamp in ns, data:
// the CDR-serialized message). Messages are read in insertion order (rowid), one row at a time.
//
// Compressed bags (`ros2 bag record --compression-format zstd`): with `--compression-mode message` each data
// blob is a zstd frame, told by its magic number (a CDR blob starts with a 0 byte); with `--compression-mode
// file` each database is NAME_i.db3.zstd, decompressed into a temporary file (sqlite needs a file) that lives
// as long as the reader.

#include <sqlite3.h>
#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "vmap/core/error.h"
#include "vmap/sources/chunk_decompression.h"
#include "vmap/sources/frame_source.h"
#include "vmap/sources/recording_reader.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

struct DatabaseCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct StatementFinalizer {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Database = std::unique_ptr<sqlite3, DatabaseCloser>;
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

// The largest message vmap can use, decompressed: an image of FrameSourceOptions::max_frame_pixels (64 MP) at
// 4 bytes a pixel, and its header. A message that claims more is damaged or hostile.
constexpr size_t kMaxMessageBytes = size_t{320} << 20;

bool IsCompressedDatabase(const fs::path& file) {
  return file.extension() == ".zstd" && file.stem().extension() == ".db3";
}

std::vector<std::string> DatabaseFiles(const std::string& path) {
  if (!fs::is_directory(path)) return {path};
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(path)) {
    if (entry.path().extension() == ".db3" || IsCompressedDatabase(entry.path())) {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end(), NaturalLess);
  if (files.empty()) {
    throw InputError("rosbag2 folder '" + path +
                     "' has no .db3 or .db3.zstd file; vmap reads rosbag2's sqlite3 "
                     "storage and MCAP (give the .mcap file itself)");
  }
  return files;
}

class Rosbag2SqliteReader : public RecordingReader {
 public:
  explicit Rosbag2SqliteReader(const std::string& path) : path_(path), files_(DatabaseFiles(path)) { Rewind(); }
  ~Rosbag2SqliteReader() override {
    statement_.reset();
    database_.reset();
    std::error_code ignored;
    if (!decompressed_dir_.empty()) fs::remove_all(decompressed_dir_, ignored);
  }
  Rosbag2SqliteReader(const Rosbag2SqliteReader&) = delete;
  Rosbag2SqliteReader& operator=(const Rosbag2SqliteReader&) = delete;

  MessageEncoding encoding() const override { return MessageEncoding::kCdr; }
  RecordingFormat format() const override { return RecordingFormat::kRosbag2; }

  void Rewind() override {
    statement_.reset();
    database_.reset();
    file_index_ = 0;
  }

  std::vector<RecordingTopic> Topics() override {
    std::map<std::string, RecordingTopic> by_topic;
    for (const std::string& file : files_) {
      Database db = Open(file);
      Statement counts = Prepare(db.get(), file,
                                 "SELECT t.name, t.type, t.serialization_format, COUNT(m.id), MIN(m.timestamp), "
                                 "MAX(m.timestamp) FROM topics t LEFT JOIN messages m ON m.topic_id = t.id "
                                 "GROUP BY t.id");
      int status;
      while ((status = sqlite3_step(counts.get())) == SQLITE_ROW) {
        const std::string name = Text(counts.get(), 0);
        RecordingTopic& topic = by_topic[name];
        const long count = sqlite3_column_int64(counts.get(), 3);
        if (topic.message_count == 0) {
          topic.first_time_ns = sqlite3_column_int64(counts.get(), 4);
        }
        topic.name = name;
        topic.type = Text(counts.get(), 1);
        if (count > 0)
          topic.last_time_ns = std::max<int64_t>(topic.last_time_ns, sqlite3_column_int64(counts.get(), 5));
        topic.message_count += count;
      }
      if (status != SQLITE_DONE) Fail(db.get(), file, "cannot count its messages");
    }
    std::vector<RecordingTopic> list;
    for (auto& [name, topic] : by_topic) list.push_back(std::move(topic));
    return list;
  }

  bool Next(const std::set<std::string>& topics, RecordedMessage* message) override {
    for (;;) {
      if (!statement_) {
        if (file_index_ >= files_.size()) return false;
        database_ = Open(files_[file_index_]);
        std::string query =
            "SELECT t.name, m.timestamp, m.data, m.id FROM messages m JOIN topics t ON "
            "m.topic_id = t.id";
        if (!topics.empty()) {
          query += " WHERE t.name IN (";
          for (size_t i = 0; i < topics.size(); ++i) query += i ? ",?" : "?";
          query += ")";
        }
        query += " ORDER BY m.id";
        statement_ = Prepare(database_.get(), files_[file_index_], query.c_str());
        int slot = 1;
        for (const std::string& topic : topics) {
          sqlite3_bind_text(statement_.get(), slot++, topic.c_str(), static_cast<int>(topic.size()), SQLITE_TRANSIENT);
        }
      }
      const int status = sqlite3_step(statement_.get());
      if (status == SQLITE_ROW) {
        message->topic = Text(statement_.get(), 0);
        message->log_time_ns = sqlite3_column_int64(statement_.get(), 1);
        const auto* blob = static_cast<const uint8_t*>(sqlite3_column_blob(statement_.get(), 2));
        const size_t size = static_cast<size_t>(std::max(sqlite3_column_bytes(statement_.get(), 2), 0));
        if (StartsWithZstdFrame(blob, size)) {
          const std::string error = DecompressZstd(blob, size, kMaxMessageBytes, &message->data);
          if (!error.empty()) {
            throw InputError("rosbag2 database '" + files_[file_index_] + "': message " +
                             std::to_string(sqlite3_column_int64(statement_.get(), 3)) + " of " + message->topic +
                             ": " + error + "; check that the recording is complete");
          }
        } else {
          message->data.assign(blob, blob + size);
        }
        message->offset = static_cast<uint64_t>(sqlite3_column_int64(statement_.get(), 3));
        return true;
      }
      if (status != SQLITE_DONE) Fail(database_.get(), files_[file_index_], "cannot read its messages");
      statement_.reset();
      database_.reset();
      ++file_index_;
    }
  }

 private:
  static std::string Text(sqlite3_stmt* statement, int column) {
    const auto* text = sqlite3_column_text(statement, column);
    return text ? reinterpret_cast<const char*>(text) : "";
  }

  [[noreturn]] static void Fail(sqlite3* db, const std::string& file, const std::string& what) {
    throw InputError("rosbag2 database '" + file + "': " + what + " (sqlite: " +
                     (db ? sqlite3_errmsg(db) : "no memory") + "); check that it is a complete rosbag2 sqlite3 file");
  }

  // The database `file` as sqlite can open it: itself, or its decompressed copy, made on first use.
  std::string Readable(const std::string& file) {
    if (!IsCompressedDatabase(file)) return file;
    auto found = decompressed_.find(file);
    if (found != decompressed_.end()) return found->second;
    if (decompressed_dir_.empty()) {
      std::string pattern = (fs::temp_directory_path() / "vmap-rosbag2-XXXXXX").string();
      if (mkdtemp(pattern.data()) == nullptr) {
        throw InputError("rosbag2 database '" + file +
                         "': cannot make a temporary folder to decompress it into; "
                         "set TMPDIR to a writable folder");
      }
      decompressed_dir_ = pattern;
    }
    const std::string copy = (fs::path(decompressed_dir_) / fs::path(file).stem()).string();
    const std::string error = DecompressZstdFile(file, copy);
    if (!error.empty()) {
      throw InputError("rosbag2 database '" + file + "': " + error +
                       "; check that the recording is complete, or set TMPDIR to a folder with room for it");
    }
    decompressed_[file] = copy;
    return copy;
  }

  Database Open(const std::string& file) {
    const std::string readable = Readable(file);
    sqlite3* raw = nullptr;
    const int status = sqlite3_open_v2(readable.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
    Database db(raw);
    if (status != SQLITE_OK) Fail(db.get(), file, "cannot open it");
    return db;
  }

  static Statement Prepare(sqlite3* db, const std::string& file, const char* query) {
    sqlite3_stmt* raw = nullptr;
    if (sqlite3_prepare_v2(db, query, -1, &raw, nullptr) != SQLITE_OK) {
      sqlite3_finalize(raw);
      Fail(db, file, "it has no rosbag2 topics and messages tables");
    }
    return Statement(raw);
  }

  std::string path_;
  std::vector<std::string> files_;
  size_t file_index_ = 0;
  Database database_;
  Statement statement_;
  std::string decompressed_dir_;                     // the decompressed copies of .db3.zstd files, if any
  std::map<std::string, std::string> decompressed_;  // file -> its copy
};

}  // namespace

std::unique_ptr<RecordingReader> OpenRosbag2(const std::string& path) {
  return std::make_unique<Rosbag2SqliteReader>(path);
}

}  // namespace vmap
