// ROS 2 bags in rosbag2's sqlite3 storage: a folder with metadata.yaml and one or more .db3 files (split
// bags: NAME_0.db3, NAME_1.db3, ... read in natural order), or one .db3 file. Each database has a `topics`
// table (id, name, type, serialization_format) and a `messages` table (topic_id, timestamp in ns, data:
// the CDR-serialized message). Messages are read in insertion order (rowid), one row at a time.
//
// Compressed bags (`ros2 bag record --compression-format zstd`): with `--compression-mode message` each data
// blob is a zstd frame, told by its magic number (a CDR blob starts with a 0 byte); with `--compression-mode
// file` each database is NAME_i.db3.zstd, decompressed into a temporary folder in TMPDIR (sqlite needs a file)
// that lives as long as the reader, is removed on an interruption too, and by the next reader when a killed
// process left it.
//
// A database is untrusted input, and sqlite runs whatever its schema says: it is opened read-only with views,
// triggers and untrusted schema functions off, and read only when `topics` and `messages` are plain tables
// (not views, not virtual tables, no generated columns) with the columns rosbag2 writes and integer primary
// keys. sqlite itself refuses a blob larger than a message may be (RecordingLimits), and every pass through
// a database has a budget of sqlite's work proportional to its size. Every file is a regular file inside the
// recording's folder (no FIFO, no symbolic link out of it), checked before sqlite opens it.

#include <sqlite3.h>

#include <algorithm>
#include <climits>
#include <filesystem>
#include <map>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/natural_less.h"
#include "vmap/sources/chunk_decompression.h"
#include "vmap/sources/recording_limits.h"
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

// sqlite's virtual machine instructions a pass may take per stored byte, and at least: a scan of rosbag2's
// tables takes well under one a byte (rows are messages of at least some bytes each).
constexpr uint64_t kInstructionsPerByte = 16;
constexpr uint64_t kMinInstructions = uint64_t{1} << 28;
constexpr int kInstructionsPerCheck = 10000;

bool IsCompressedDatabase(const fs::path& file) {
  return file.extension() == ".zstd" && file.stem().extension() == ".db3";
}

// One database of the recording, checked to be a regular file inside the recording's folder.
struct DatabaseFile {
  std::string path;  // as named: the recording's folder / name, or the .db3 file given
  fs::path folder;   // empty for a .db3 file given on its own
  std::string name;
  uint64_t size = 0;
};

ContainedFile OpenDatabaseFile(const DatabaseFile& file) {
  std::string why_not;
  std::optional<ContainedFile> opened = file.folder.empty() ? ContainedFile::OpenRegular(file.path, &why_not)
                                                            : ContainedFile::Open(file.folder, file.name, &why_not);
  if (!opened) {
    throw InputError("rosbag2 database '" + file.path + "' " + why_not +
                     "; a recording's databases are regular files inside its folder");
  }
  return std::move(*opened);
}

std::vector<DatabaseFile> DatabaseFiles(const std::string& path) {
  std::vector<DatabaseFile> files;
  if (!fs::is_directory(path)) {
    files.push_back({path, {}, "", 0});
  } else {
    for (const auto& entry : fs::directory_iterator(path)) {
      if (entry.path().extension() == ".db3" || IsCompressedDatabase(entry.path())) {
        files.push_back({entry.path().string(), path, entry.path().filename().string(), 0});
      }
    }
    std::sort(files.begin(), files.end(),
              [](const DatabaseFile& a, const DatabaseFile& b) { return NaturalLess(a.path, b.path); });
  }
  if (files.empty()) {
    throw InputError("rosbag2 folder '" + path +
                     "' has no .db3 or .db3.zstd file; vmap reads rosbag2's sqlite3 "
                     "storage and MCAP (give the .mcap file itself)");
  }
  for (DatabaseFile& file : files) file.size = OpenDatabaseFile(file).size();  // refused before any is read
  return files;
}

struct TopicRow {
  std::string name;
  std::string type;
};

class Rosbag2SqliteReader : public RecordingReader {
 public:
  Rosbag2SqliteReader(const std::string& path, const RecordingLimits& limits)
      : path_(path), files_(DatabaseFiles(path)), limits_(limits) {
    uint64_t stored = 0;
    for (const DatabaseFile& file : files_) stored += file.size;
    budget_ = PassBudget(limits, stored);
    instruction_checks_ = (stored * kInstructionsPerByte + kMinInstructions) / kInstructionsPerCheck;
    Rewind();
  }
  ~Rosbag2SqliteReader() override {
    statement_.reset();
    database_.reset();
  }
  Rosbag2SqliteReader(const Rosbag2SqliteReader&) = delete;
  Rosbag2SqliteReader& operator=(const Rosbag2SqliteReader&) = delete;

  MessageEncoding encoding() const override { return MessageEncoding::kCdr; }
  RecordingFormat format() const override { return RecordingFormat::kRosbag2; }

  void Rewind() override {
    statement_.reset();
    database_.reset();
    file_index_ = 0;
    budget_.Reset();
    checks_done_ = 0;
  }

  std::vector<RecordingTopic> Topics() override {
    Rewind();
    std::map<std::string, RecordingTopic> by_topic;
    for (const DatabaseFile& file : files_) {
      Database db = Open(file);
      const std::map<int64_t, TopicRow> topics = ReadTopics(db.get(), file);
      // Counted here from one scan of the rows, not by sqlite's GROUP BY, which sorts them all first.
      std::map<int64_t, RecordingTopic> counted;
      Statement rows = Prepare(db.get(), file, "SELECT topic_id, timestamp FROM messages");
      int status;
      while ((status = sqlite3_step(rows.get())) == SQLITE_ROW) {
        const int64_t id = sqlite3_column_int64(rows.get(), 0), time = sqlite3_column_int64(rows.get(), 1);
        RecordingTopic& topic = counted[id];
        if (topic.message_count++ == 0) topic.first_time_ns = topic.last_time_ns = time;
        topic.first_time_ns = std::min(topic.first_time_ns, time);
        topic.last_time_ns = std::max(topic.last_time_ns, time);
      }
      if (status != SQLITE_DONE) Fail(db.get(), file, "cannot count its messages");
      for (const auto& [id, row] : topics) {
        RecordingTopic& topic = by_topic[row.name];
        const auto found = counted.find(id);
        topic.name = row.name;
        topic.type = row.type;
        if (found == counted.end()) continue;
        const RecordingTopic& these = found->second;
        topic.first_time_ns =
            topic.message_count == 0 ? these.first_time_ns : std::min(topic.first_time_ns, these.first_time_ns);
        topic.last_time_ns = std::max(topic.last_time_ns, these.last_time_ns);
        topic.message_count += these.message_count;
      }
    }
    Rewind();
    std::vector<RecordingTopic> list;
    for (auto& [name, topic] : by_topic) list.push_back(std::move(topic));
    return list;
  }

  bool Next(const std::set<std::string>& topics, RecordedMessage* message) override {
    for (;;) {
      if (!statement_) {
        if (file_index_ >= files_.size()) return false;
        const DatabaseFile& file = files_[file_index_];
        database_ = Open(file);
        topic_names_.clear();
        for (auto& [id, row] : ReadTopics(database_.get(), file)) {
          if (topics.empty() || topics.count(row.name)) topic_names_[id] = row.name;
        }
        // The blob only when it may be a message: a larger one is named, not loaded (length() reads no data).
        std::string query =
            "SELECT topic_id, timestamp, CASE WHEN length(data) <= ?1 THEN data END, length(data), id FROM messages";
        if (!topics.empty()) {
          query += " WHERE topic_id IN (";
          bool first = true;
          for (const auto& [id, name] : topic_names_) {
            query += (first ? "" : ",") + std::to_string(id);
            first = false;
          }
          query += ")";
        }
        query += " ORDER BY id";
        statement_ = Prepare(database_.get(), file, query.c_str());
        sqlite3_bind_int64(statement_.get(), 1, static_cast<sqlite3_int64>(MaxBlobBytes()));
      }
      const DatabaseFile& file = files_[file_index_];
      const int status = sqlite3_step(statement_.get());
      if (status == SQLITE_ROW) {
        const auto name = topic_names_.find(sqlite3_column_int64(statement_.get(), 0));
        if (name == topic_names_.end()) continue;  // a message of a topic the database does not list
        const int64_t id = sqlite3_column_int64(statement_.get(), 4);
        message->topic = name->second;
        message->log_time_ns = sqlite3_column_int64(statement_.get(), 1);
        message->offset = static_cast<uint64_t>(id);
        const int64_t length = sqlite3_column_int64(statement_.get(), 3);
        if (length < 0 || static_cast<uint64_t>(length) > MaxBlobBytes()) {
          MessageFails(file, id, message->topic,
                       "it holds " + std::to_string(length) +
                           " bytes, more than a message of the largest frames needs; "
                           "it is damaged or crafted");
        }
        const auto* blob = static_cast<const uint8_t*>(sqlite3_column_blob(statement_.get(), 2));
        const size_t size = static_cast<size_t>(std::max(sqlite3_column_bytes(statement_.get(), 2), 0));
        if (StartsWithZstdFrame(blob, size)) {
          const uint64_t most = std::min(limits_.max_message_bytes, budget_.bytes_left());
          bool too_large = false;
          const std::string error = DecompressZstd(blob, size, static_cast<size_t>(most), &message->data, &too_large);
          if (too_large) {
            MessageFails(file, id, message->topic,
                         most < limits_.max_message_bytes
                             ? budget_.WhyBytesExceeded()
                             : "it decompresses to more than the " + std::to_string(most) +
                                   " bytes a message of the largest frames needs; it is damaged or crafted");
          }
          if (!error.empty()) {
            throw InputError("rosbag2 database '" + file.path + "': message " + std::to_string(id) + " of " +
                             message->topic + ": " + error + "; check that the recording is complete");
          }
          budget_.Spend(message->data.size());  // fits: `most` was at most what is left
        } else {
          message->data.assign(blob, blob + size);
        }
        return true;
      }
      if (status != SQLITE_DONE) Fail(database_.get(), file, "cannot read its messages");
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

  uint64_t MaxBlobBytes() const { return std::min<uint64_t>(limits_.max_message_bytes, INT_MAX - 1); }

  [[noreturn]] void MessageFails(const DatabaseFile& file, int64_t id, const std::string& topic,
                                 const std::string& problem) const {
    throw RecordingLimitExceeded("rosbag2 database '" + file.path + "': message " + std::to_string(id) + " of " +
                                 topic + ": " + problem);
  }

  [[noreturn]] void Fail(sqlite3* db, const DatabaseFile& file, const std::string& what) const {
    const int code = db ? sqlite3_errcode(db) : SQLITE_NOMEM;
    if (code == SQLITE_INTERRUPT) {
      throw RecordingLimitExceeded("rosbag2 database '" + file.path + "': " + what +
                                   ": reading it took more work than a " + "database of its size needs (" +
                                   std::to_string(checks_done_ * kInstructionsPerCheck) +
                                   " sqlite instructions); it is damaged or crafted");
    }
    if (code == SQLITE_TOOBIG) {
      throw RecordingLimitExceeded("rosbag2 database '" + file.path + "': " + what + ": it holds a value larger than " +
                                   std::to_string(MaxBlobBytes()) +
                                   " bytes, more than a message of the largest "
                                   "frames needs; it is damaged or crafted");
    }
    throw InputError("rosbag2 database '" + file.path + "': " + what + " (sqlite: " +
                     (db ? sqlite3_errmsg(db) : "no memory") + "); check that it is a complete rosbag2 sqlite3 file");
  }

  // The database `file` as sqlite can open it: itself, or its decompressed copy, made on first use.
  std::string Readable(const DatabaseFile& file) {
    const ContainedFile opened = OpenDatabaseFile(file);  // checked again: it may have changed since
    if (!IsCompressedDatabase(file.path)) {
      std::error_code ec;
      const fs::path real = fs::canonical(file.path, ec);
      return ec ? file.path : real.string();
    }
    auto found = decompressed_.find(file.path);
    if (found != decompressed_.end()) return found->second;
    if (!decompressed_dir_) {
      decompressed_dir_ = RethrowAsInputError(
          [&] {
            return ErrorContext{"rosbag2 database '" + file.path + "': cannot make a folder to decompress it into",
                                "set TMPDIR to a writable folder"};
          },
          [&] { return std::make_unique<TemporaryDirectory>(fs::temp_directory_path() / "vmap-rosbag2"); });
    }
    const std::string copy = (decompressed_dir_->path() / fs::path(file.path).stem()).string();
    const std::string error = DecompressZstdFile(opened, copy, limits_.PassBytes(file.size));
    if (!error.empty()) {
      std::error_code ignored;
      fs::remove(copy, ignored);
      throw RecordingLimitExceeded(
          "rosbag2 database '" + file.path + "': " + error +
          "; check that the recording is complete, or set TMPDIR to a folder with room for it");
    }
    decompressed_[file.path] = copy;
    return copy;
  }

  static int Progress(void* reader) {
    auto* self = static_cast<Rosbag2SqliteReader*>(reader);
    return ++self->checks_done_ > self->instruction_checks_ ? 1 : 0;
  }

  Database Open(const DatabaseFile& file) {
    const std::string readable = Readable(file);
    sqlite3* raw = nullptr;
    const int status = sqlite3_open_v2(readable.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
    Database db(raw);
    if (status != SQLITE_OK) Fail(db.get(), file, "cannot open it");
    sqlite3_extended_result_codes(db.get(), 0);
    const std::pair<int, int> settings[] = {{SQLITE_DBCONFIG_DEFENSIVE, 1},
                                            {SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0},
                                            {SQLITE_DBCONFIG_ENABLE_VIEW, 0},
                                            {SQLITE_DBCONFIG_ENABLE_TRIGGER, 0}};
    for (const auto& [option, value] : settings) sqlite3_db_config(db.get(), option, value, nullptr);
    sqlite3_limit(db.get(), SQLITE_LIMIT_LENGTH, static_cast<int>(MaxBlobBytes()));
    sqlite3_progress_handler(db.get(), kInstructionsPerCheck, &Progress, this);
    CheckSchema(db.get(), file);
    return db;
  }

  // `topics` and `messages` as rosbag2 makes them: tables, with its columns, and integer primary keys.
  void CheckSchema(sqlite3* db, const DatabaseFile& file) const {
    const std::pair<const char*, std::vector<const char*>> tables[] = {
        {"topics", {"id", "name", "type", "serialization_format"}},
        {"messages", {"id", "topic_id", "timestamp", "data"}}};
    for (const auto& entry : tables) {
      const char* table = entry.first;
      const std::vector<const char*>& columns = entry.second;
      const auto refuse = [&](const std::string& why) {
        throw InputError("rosbag2 database '" + file.path + "': its " + table + " " + why +
                         "; vmap reads the tables rosbag2's sqlite3 storage writes");
      };
      Statement kind = Prepare(db, file, "SELECT type, sql FROM sqlite_schema WHERE name = ?1");
      sqlite3_bind_text(kind.get(), 1, table, -1, SQLITE_STATIC);
      if (sqlite3_step(kind.get()) != SQLITE_ROW) refuse("table is missing");
      std::string sql = Text(kind.get(), 1);
      std::transform(sql.begin(), sql.end(), sql.begin(), [](unsigned char c) { return std::toupper(c); });
      const bool is_virtual =
          sql.compare(sql.find_first_not_of(" \t\r\n") == std::string::npos ? 0 : sql.find_first_not_of(" \t\r\n"),
                      std::string::npos, "CREATE VIRTUAL", 0, 14) == 0;
      if (Text(kind.get(), 0) != "table" || is_virtual) {
        refuse(is_virtual ? "is a virtual table, not a table" : "is a " + Text(kind.get(), 0) + ", not a table");
      }
      // table_xinfo lists generated columns too (hidden 2 or 3): computed on every read, never rosbag2's.
      Statement info = Prepare(db, file, ("PRAGMA table_xinfo(" + std::string(table) + ")").c_str());
      std::map<std::string, std::pair<std::string, int>> found;  // name -> declared type, primary key
      int status;
      while ((status = sqlite3_step(info.get())) == SQLITE_ROW) {
        if (sqlite3_column_int(info.get(), 6) != 0) refuse("table has a generated column");
        found[Text(info.get(), 1)] = {Text(info.get(), 2), sqlite3_column_int(info.get(), 5)};
      }
      if (status != SQLITE_DONE) Fail(db, file, std::string("cannot read the columns of ") + table);
      for (const char* column : columns) {
        if (!found.count(column)) refuse(std::string("table has no column ") + column);
      }
      std::string id_type = found["id"].first;
      std::transform(id_type.begin(), id_type.end(), id_type.begin(), [](unsigned char c) { return std::toupper(c); });
      if (id_type != "INTEGER" || found["id"].second != 1) refuse("table's id is not its INTEGER PRIMARY KEY");
    }
  }

  std::map<int64_t, TopicRow> ReadTopics(sqlite3* db, const DatabaseFile& file) const {
    std::map<int64_t, TopicRow> topics;
    Statement rows = Prepare(db, file, "SELECT id, name, type FROM topics");
    int status;
    while ((status = sqlite3_step(rows.get())) == SQLITE_ROW) {
      topics[sqlite3_column_int64(rows.get(), 0)] = {Text(rows.get(), 1), Text(rows.get(), 2)};
    }
    if (status != SQLITE_DONE) Fail(db, file, "cannot read its topics");
    return topics;
  }

  Statement Prepare(sqlite3* db, const DatabaseFile& file, const char* query) const {
    sqlite3_stmt* raw = nullptr;
    if (sqlite3_prepare_v2(db, query, -1, &raw, nullptr) != SQLITE_OK) {
      sqlite3_finalize(raw);
      Fail(db, file, "it has no rosbag2 topics and messages tables");
    }
    return Statement(raw);
  }

  std::string path_;
  std::vector<DatabaseFile> files_;
  RecordingLimits limits_;
  PassBudget budget_;                // of the zstd messages of this pass
  uint64_t instruction_checks_ = 0;  // sqlite's progress checks a pass may take
  uint64_t checks_done_ = 0;
  size_t file_index_ = 0;
  Database database_;
  Statement statement_;
  std::map<int64_t, std::string> topic_names_;            // of the database being read: the wanted topics by id
  std::unique_ptr<TemporaryDirectory> decompressed_dir_;  // the decompressed copies of .db3.zstd files, if any
  std::map<std::string, std::string> decompressed_;       // file -> its copy
};

}  // namespace

std::unique_ptr<RecordingReader> OpenRosbag2(const std::string& path, const RecordingLimits& limits) {
  return std::make_unique<Rosbag2SqliteReader>(path, limits);
}

}  // namespace vmap
