// Recordings made to hurt (issue 38): FIFOs and links in place of files, sqlite databases whose tables are
// views or computed, chunks that announce or decompress to gigabytes, malformed messages and calibrations. Each
// must end in one clear error (or a skipped message), quickly and in bounded memory, and never in a hang.

#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/sources/frame_source.h"
#include "vmap/sources/recording_limits.h"
#include "vmap/sources/recording_reader.h"
#include "vmap/sources/recording_source.h"
#include "vmap/sources/ros_image_messages.h"
#include "vmap/testing/hostile_recordings.h"
#include "vmap/testing/recording_writer.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using testing::RunVmapBounded;
using testing::TestMessage;

constexpr long kGiB = 1L << 30;
const cv::Size kSize(96, 64);

cv::Mat FrameImage(int i) {
  cv::Mat image(kSize, CV_8UC3);
  cv::RNG rng(i + 1);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

// `count` frames on /cam/image_raw (bgr8), 0.1 s apart.
std::vector<TestMessage> Frames(MessageEncoding encoding, int count, int first = 0) {
  std::vector<TestMessage> messages;
  for (int i = first; i < first + count; ++i) {
    const int64_t ns = 1'000'000'000 + i * 100'000'000LL;
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", ns,
                        testing::SerializeImage(encoding, ns * 1e-9, "cam", FrameImage(i), "bgr8")});
  }
  return messages;
}

// Runs vmap with these arguments and expects one clear refusal: status 2, a `vmap: error:` line naming
// `expected`, within 20 seconds and 1 GB.
void ExpectRefused(const std::vector<std::string>& arguments, const std::string& expected) {
  std::string command;
  for (const std::string& a : arguments) command += " " + a;
  const testing::BoundedRun run = RunVmapBounded(arguments, 20.0);
  EXPECT_FALSE(run.timed_out) << command << "\n" << run.output;
  EXPECT_EQ(run.status, 2) << command << "\n" << run.output;
  EXPECT_NE(run.output.find("vmap: error:"), std::string::npos) << command << "\n" << run.output;
  EXPECT_NE(run.output.find(expected), std::string::npos) << command << "\n" << run.output;
  EXPECT_LT(run.max_rss_bytes, kGiB) << command;
}

// ---- 4. FIFOs and devices, 9. links out of a recording's folder --------------------------------------------

TEST(HostileRecordings, FifosAreRefusedBeforeAnythingOpensThem) {
  testing::ScopedTempDir tmp;
  const fs::path folder = tmp.path() / "rosbag2";
  fs::create_directories(folder);
  std::ofstream(folder / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 5\n";
  for (const fs::path& fifo : {tmp.path() / "f.bag", tmp.path() / "f.mcap", tmp.path() / "f.db3", tmp.path() / "f.mp4",
                               tmp.path() / "f", folder / "rosbag2_0.db3"}) {
    ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0) << fifo;
  }
  const std::string out = (tmp.path() / "out").string();
  for (const char* name : {"f.bag", "f.mcap", "f.db3"}) {
    const std::string path = (tmp.path() / name).string();
    ExpectRefused({"info", path}, "is not a regular file");
    ExpectRefused({"build", path, "-o", out}, "is not a regular file");
    EXPECT_THROW(OpenRecording(path), InputError) << path;
  }
  ExpectRefused({"info", folder.string()}, "is not a regular file");
  ExpectRefused({"build", folder.string(), "-o", out}, "is not a regular file");
  ExpectRefused({"build", (tmp.path() / "f.mp4").string(), "-o", out}, "is not a regular file or a folder");
  ExpectRefused({"build", (tmp.path() / "f").string(), "-o", out}, "is not a regular file or a folder");
  EXPECT_FALSE(fs::exists(out));
}

TEST(HostileRecordings, FilesLinkedFromOutsideARecordingsFolderAreRefused) {
  testing::ScopedTempDir tmp;
  // A real database elsewhere, and a rosbag2 folder whose .db3 is a link to it.
  testing::WriteRosbag2((tmp.path() / "elsewhere").string(), Frames(MessageEncoding::kCdr, 3));
  const fs::path folder = tmp.path() / "linked";
  fs::create_directories(folder);
  fs::copy_file(tmp.path() / "elsewhere/metadata.yaml", folder / "metadata.yaml");
  fs::create_symlink(tmp.path() / "elsewhere/elsewhere_0.db3", folder / "linked_0.db3");
  try {
    OpenRecording(folder.string())->Topics();
    FAIL() << "a database linked from outside the folder was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("resolves outside"), std::string::npos) << error.what();
  }
  // The same for the .mcap file of a folder written with the MCAP storage plugin.
  testing::WriteMcap((tmp.path() / "elsewhere.mcap").string(), Frames(MessageEncoding::kCdr, 3), "zstd");
  const fs::path mcap_folder = tmp.path() / "linked_mcap";
  fs::create_directories(mcap_folder);
  fs::copy_file(tmp.path() / "elsewhere/metadata.yaml", mcap_folder / "metadata.yaml");
  fs::create_symlink(tmp.path() / "elsewhere.mcap", mcap_folder / "linked_mcap_0.mcap");
  EXPECT_THROW(OpenRecording(mcap_folder.string()), InputError);
  // A link inside the folder, to a file of the folder, is still read.
  fs::rename(folder / "linked_0.db3", folder / "link");
  fs::copy_file(tmp.path() / "elsewhere/elsewhere_0.db3", folder / "real.db3.data");
  fs::create_symlink("real.db3.data", folder / "linked_0.db3");
  EXPECT_EQ(OpenRecording(folder.string())->Topics().at(0).message_count, 3);
}

// ---- 5. Databases that are not what rosbag2 writes -----------------------------------------------------------

// A .db3 made of `schema` (SQL run as is).
fs::path Database(const fs::path& dir, const std::string& name, const std::string& schema) {
  const fs::path file = dir / name;
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, schema.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
  return file;
}

const char kTopics[] =
    "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format "
    "TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
    "INSERT INTO topics VALUES (1, '/cam/image_raw', 'sensor_msgs/msg/Image', 'cdr', '');";

TEST(HostileRecordings, DatabasesWithViewsOrComputedColumnsAreRefusedAtOnce) {
  testing::ScopedTempDir tmp;
  const std::string topics = kTopics;
  const struct {
    const char* name;
    std::string schema;
    const char* expected;
  } cases[] = {
      // The 8 KB database whose `messages` is a recursive view: sqlite would count forever.
      {"recursive.db3",
       topics + "CREATE VIEW messages AS WITH RECURSIVE n(id) AS (SELECT 1 UNION ALL SELECT id + 1 FROM n) "
                "SELECT id, 1 AS topic_id, id AS timestamp, x'00' AS data FROM n;",
       "is a view, not a table"},
      // A view computing a 900 MB blob for every row.
      {"zeroblob.db3",
       topics + "CREATE VIEW messages AS SELECT 1 AS id, 1 AS topic_id, 0 AS timestamp, zeroblob(900000000) AS data;",
       "is a view, not a table"},
      // A table whose data column is computed on every read.
      {"generated.db3",
       topics + "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, "
                "data BLOB GENERATED ALWAYS AS (zeroblob(900000000)) VIRTUAL);"
                "INSERT INTO messages (topic_id, timestamp) VALUES (1, 0);",
       "generated column"},
      {"no_data.db3", topics + "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER);",
       "has no column data"},
      {"text_id.db3",
       topics + "CREATE TABLE messages(id TEXT PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB);",
       "is not its INTEGER PRIMARY KEY"},
  };
  for (const auto& c : cases) {
    const fs::path file = Database(tmp.path(), c.name, c.schema);
    ExpectRefused({"info", file.string()}, c.expected);
    ExpectRefused({"build", file.string(), "-o", (tmp.path() / "out").string()}, c.expected);
  }
}

TEST(HostileRecordings, ABlobLargerThanAMessageIsNamedNotLoaded) {
  testing::ScopedTempDir tmp;
  const fs::path file =
      Database(tmp.path(), "big.db3",
               std::string(kTopics) +
                   "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB);"
                   "INSERT INTO messages (topic_id, timestamp, data) VALUES (1, 0, zeroblob(5000));");
  RecordingLimits limits;
  limits.max_message_bytes = 4096;
  const std::unique_ptr<RecordingReader> reader = OpenRecording(file.string(), limits);
  RecordedMessage message;
  try {
    reader->Next({}, &message);
    FAIL() << "a blob of 5000 bytes was read under a limit of 4096";
  } catch (const RecordingLimitExceeded& error) {
    EXPECT_NE(std::string(error.what()).find("message 1 of /cam/image_raw"), std::string::npos) << error.what();
  }
}

// ---- 6, 7. Chunks that announce, or decompress to, more than frames need ----------------------------------

TEST(HostileRecordings, AChunkAnnouncingMoreThanTheLargestFrameNeedsIsRefusedBeforeItIsAllocated) {
  testing::ScopedTempDir tmp;
  // 1.5 GiB of zeros after two frames and 2 MB of noise, in 2 MB: read as it announces itself, it took 1.5 GiB
  // and more (the 2.3 MB MCAP peaked at 3.1 GB).
  std::vector<TestMessage> messages = Frames(MessageEncoding::kCdr, 2);
  std::vector<uint8_t> noise(2 << 20);
  cv::randu(cv::Mat(1, static_cast<int>(noise.size()), CV_8U, noise.data()), 0, 256);
  messages.push_back({"/noise", "std_msgs/ByteMultiArray", 1'000'000'000, noise});
  const fs::path mcap = tmp.path() / "bomb.mcap";
  testing::WriteMcapBomb(mcap.string(), messages, "zstd", 3 * (kGiB / 2));
  ASSERT_LT(fs::file_size(mcap), 3u << 20);
  ExpectRefused({"info", mcap.string()}, "a chunk of the largest frames needs");
  ExpectRefused({"build", mcap.string(), "-o", (tmp.path() / "out").string()}, "a chunk of the largest frames needs");
  const fs::path bag = tmp.path() / "bomb.bag";
  testing::Ros1Chunk chunk;
  chunk.messages = Frames(MessageEncoding::kRos1, 2);
  chunk.compression = "lz4";  // at most 255:1, so that the chunk's stored size passes for a plausible one
  chunk.padding = 3 * (kGiB / 2);
  testing::WriteRos1BagChunks(bag.string(), {chunk});
  ExpectRefused({"info", bag.string()}, "a chunk of the largest frames needs");
}

TEST(HostileRecordings, ChunksOfZerosEndTheirPassWithinItsBudget) {
  testing::ScopedTempDir tmp;
  // The CPU bomb: a bag of 100 bz2 chunks of zeros (here 48 MiB each), each allowed alone; reading
  // them all took a minute. The budget of one pass (256 MiB and 64 times the bag's size) ends it at the sixth.
  testing::Ros1Chunk chunk;
  chunk.compression = "bz2";
  const std::string records = testing::Ros1ChunkRecords(Frames(MessageEncoding::kRos1, 1), 48 << 20);
  chunk.stored = testing::CompressedWithZeros("bz2", records, 48 << 20);
  chunk.announced_size = records.size() + (48 << 20);
  const fs::path bag = tmp.path() / "zeros.bag";
  testing::WriteRos1BagChunks(bag.string(), std::vector<testing::Ros1Chunk>(100, chunk));
  ASSERT_LT(fs::file_size(bag), 4u << 20);
  ExpectRefused({"info", bag.string()}, "decompression bomb");
  // The pass ends after a few chunks of the 100 (each of a frame and 48 MiB of zeros), whatever reads it.
  const std::unique_ptr<RecordingReader> reader = OpenRecording(bag.string());
  RecordedMessage message;
  int messages = 0;
  EXPECT_THROW(
      {
        while (reader->Next({}, &message)) ++messages;
      },
      RecordingLimitExceeded);
  EXPECT_LE(messages, 2 * 10);
}

TEST(HostileRecordings, ChunksOfEmptyRecordsEndTheirPassWithinItsBudget) {
  // Zeros parse as ROS 1 records of no header and no data, each a message of connection 0 (rosbag numbers
  // connections from 0): a chunk of them is millions of messages.
  testing::ScopedTempDir tmp;
  RecordingLimits limits;
  limits.pass_records_floor = 1000;
  std::string records = testing::Ros1ChunkRecords(Frames(MessageEncoding::kRos1, 1), 0, /*first_connection=*/0);
  records.append(1 << 20, '\0');
  testing::Ros1Chunk chunk;
  chunk.compression = "lz4";
  chunk.stored = testing::CompressBytes("lz4", records);
  chunk.announced_size = records.size();
  const fs::path bag = tmp.path() / "records.bag";
  testing::WriteRos1BagChunks(bag.string(), {chunk});
  const std::unique_ptr<RecordingReader> reader = OpenRecording(bag.string(), limits);
  RecordedMessage message;
  try {
    while (reader->Next({}, &message)) {
    }
    FAIL() << "131,072 empty records were parsed";
  } catch (const RecordingLimitExceeded& error) {
    EXPECT_NE(std::string(error.what()).find(" records (one per 4 of its "), std::string::npos) << error.what();
  }
}

TEST(HostileRecordings, TheBudgetIsPerPassAndScalesWithTheRecording) {
  RecordingLimits limits;
  limits.pass_bytes_floor = 1000;
  limits.pass_bytes_per_stored_byte = 10;
  limits.pass_records_floor = 3;
  limits.stored_bytes_per_record = 50;
  PassBudget budget(limits, 100);  // 1000 + 10 x 100 bytes, 3 + 100 / 50 records
  EXPECT_EQ(budget.Spend(1500), "");
  EXPECT_EQ(budget.Spend(500), "");
  EXPECT_NE(budget.Spend(1).find("decompression bomb"), std::string::npos);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(budget.CountRecord(), "");
  EXPECT_NE(budget.CountRecord().find("more than 5 records"), std::string::npos);
  budget.Reset();
  EXPECT_EQ(budget.Spend(2000), "");
  EXPECT_EQ(budget.CountRecord(), "");
  // The limits follow the frames: a message of the 64-megapixel cap at 4 bytes a pixel fits, one more does not.
  const RecordingLimits frames = RecordingLimits::ForFrames(kMaxFramePixels);
  EXPECT_GE(frames.max_message_bytes, 4ull * 8192 * 8192);
  EXPECT_LT(frames.max_message_bytes, 4ull * 8192 * 8192 + (2u << 20));
  EXPECT_GT(frames.max_chunk_bytes, frames.max_message_bytes);
}

// ---- 8. A database compressed whole: a capped copy, removed on every exit ---------------------------------

TEST(HostileRecordings, ACompressedDatabaseIsDecompressedUnderACapAndItsCopyNeverStays) {
  testing::ScopedTempDir tmp;
  const fs::path scratch = tmp.path() / "tmpdir";
  fs::create_directories(scratch);
  // A folder whose .db3.zstd holds a real database followed by 600 MiB of zeros: 600 MiB in TMPDIR before.
  const fs::path folder = tmp.path() / "bomb";
  testing::WriteRosbag2(folder.string(), Frames(MessageEncoding::kCdr, 2));
  const fs::path db = folder / "bomb_0.db3";
  std::ifstream in(db, std::ios::binary);
  const std::string plain((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(folder / "bomb_0.db3.zstd", std::ios::binary) << testing::CompressedWithZeros("zstd", plain, 600 << 20);
  fs::remove(db);
  // A copy left by a process that was killed (its pid runs no more) is removed by the next reader.
  const fs::path stale = scratch / ".vmap-rosbag2.partial-999999999-1";
  fs::create_directories(stale);
  std::ofstream(stale / "x_0.db3") << "left behind";
  const std::string environment = "TMPDIR=" + testing::Quote(scratch);
  const testing::CliResult run = testing::RunVmap("info " + testing::Quote(folder), environment);
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("decompression bomb"), std::string::npos) << run.output;
  EXPECT_TRUE(fs::is_empty(scratch)) << "the copy, and the stale one, are gone";
  // A good one is read, and its copy removed at the end.
  testing::WriteRosbag2((tmp.path() / "good").string(), Frames(MessageEncoding::kCdr, 4), "file");
  const testing::CliResult good = testing::RunVmap("info " + testing::Quote(tmp.path() / "good"), environment);
  EXPECT_EQ(good.status, 0) << good.output;
  EXPECT_NE(good.output.find("/cam/image_raw"), std::string::npos) << good.output;
  EXPECT_TRUE(fs::is_empty(scratch));
}

// ---- 10. No usable frame ----------------------------------------------------------------------------------

TEST(HostileRecordings, ARecordingWithoutAUsableFrameBuildsNoMap) {
  testing::ScopedTempDir tmp;
  const std::string out = (tmp.path() / "out").string();
  // An image topic without messages (rosbag2 lists topics whatever was recorded).
  const fs::path empty = Database(tmp.path(), "empty.db3",
                                  std::string(kTopics) +
                                      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
                                      "timestamp INTEGER NOT NULL, data BLOB NOT NULL);");
  ExpectRefused({"build", empty.string(), "-o", out}, "has no messages");
  // --first past the last frame.
  const fs::path mcap = tmp.path() / "five.mcap";
  testing::WriteMcap(mcap.string(), Frames(MessageEncoding::kCdr, 5), "zstd");
  ExpectRefused({"build", mcap.string(), "-o", out, "--first", "7"}, "leaves none of the 5 frames");
  // Every image undecodable (an encoding vmap does not read).
  std::vector<TestMessage> odd;
  for (int i = 0; i < 4; ++i) {
    odd.push_back({"/cam/image_raw", "sensor_msgs/Image", 1'000'000'000LL + i,
                   testing::SerializeImage(MessageEncoding::kCdr, 1.0 + i, "cam", FrameImage(i), "yuv422")});
  }
  testing::WriteMcap((tmp.path() / "odd.mcap").string(), odd, "zstd");
  ExpectRefused({"build", (tmp.path() / "odd.mcap").string(), "-o", out}, "could be used");
  EXPECT_FALSE(fs::exists(out));
}

// ---- 11. What the reader refuses is never written ---------------------------------------------------------

TEST(HostileRecordings, CalibrationsAMapCouldNotHoldAreRefusedAndRatesNoCameraHasAreUnknown) {
  testing::ScopedTempDir tmp;
  const double nan = std::nan("");
  const struct {
    cv::Matx33d k;
    std::vector<double> d;
  } bad[] = {{{nan, 0, 47.5, 0, 80, 31.5, 0, 0, 1}, {}},
             {{-80, 0, 47.5, 0, 80, 31.5, 0, 0, 1}, {}},
             {{1e300, 0, 47.5, 0, 80, 31.5, 0, 0, 1}, {}},
             {{80, 0, 47.5, 0, 0, 31.5, 0, 0, 1}, {}},
             {{80, 0, 47.5, 0, 80, 31.5, 0, 0, 1}, {nan, 0, 0, 0, 0}},
             {{80, 0, 47.5, 0, 80, 31.5, 0, 0, 1}, {1e9, 0, 0, 0, 0}}};
  int n = 0;
  for (const auto& c : bad) {
    std::vector<TestMessage> messages = Frames(MessageEncoding::kCdr, 6);
    messages.insert(messages.begin(),
                    {"/cam/camera_info", "sensor_msgs/CameraInfo", 999'000'000,
                     testing::SerializeCameraInfo(MessageEncoding::kCdr, 1.0, "cam", kSize, "plumb_bob", c.d, c.k)});
    const fs::path mcap = tmp.path() / ("camera" + std::to_string(n++) + ".mcap");
    testing::WriteMcap(mcap.string(), messages, "zstd");
    ExpectRefused({"build", mcap.string(), "-o", (tmp.path() / "out").string()}, "--camera none");
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
  // Messages 1 ns apart: no camera's rate; the map says it is unknown, and reads back.
  std::vector<TestMessage> fast = Frames(MessageEncoding::kCdr, 8);
  for (size_t i = 0; i < fast.size(); ++i) fast[i].log_time_ns = 1'000'000'000 + static_cast<int64_t>(i);
  testing::WriteMcap((tmp.path() / "fast.mcap").string(), fast, "zstd");
  std::string output;
  ASSERT_EQ(testing::RunVmap(
                "build " + testing::Quote(tmp.path() / "fast.mcap") + " -o " + testing::Quote(tmp.path() / "fast_map"),
                &output),
            0)
      << output;
  EXPECT_EQ(testing::RunVmap("info " + testing::Quote(tmp.path() / "fast_map"), &output), 0) << output;
}

// ---- 12. A malformed message OpenCV refuses is that message's problem -------------------------------------

TEST(HostileRecordings, AMono16ImageWithAnOddStepIsSkippedNamingIt) {
  cv::Mat wide(kSize, CV_16UC1, cv::Scalar(1000));
  const std::vector<uint8_t> odd =
      testing::SerializeImage(MessageEncoding::kRos1, 1.0, "cam", wide, "mono16", /*padding=*/1);
  EXPECT_THROW(DecodeImageMessage(odd.data(), odd.size(), "sensor_msgs/Image", MessageEncoding::kRos1, "message 3"),
               InputError);
  testing::ScopedTempDir tmp;
  std::vector<TestMessage> messages = Frames(MessageEncoding::kCdr, 6);
  messages[2].data =
      testing::SerializeImage(MessageEncoding::kCdr, messages[2].log_time_ns * 1e-9, "cam", wide, "mono16", 1);
  const fs::path mcap = tmp.path() / "odd_step.mcap";
  testing::WriteMcap(mcap.string(), messages, "zstd");
  FrameSourceOptions options;
  const std::unique_ptr<FrameSource> source = OpenFrameSource(mcap.string(), options);
  int frames = 0;
  while (source->Next()) ++frames;
  EXPECT_EQ(frames, 5);
  EXPECT_EQ(source->skipped_frames(), 1);
}

}  // namespace
}  // namespace vmap
