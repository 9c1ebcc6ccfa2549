// Issue 38's campaign again, on two builds of vmap side by side: hostile recordings, concurrent writers of a
// map, broken experiences and runs. Every case's input is made here (small files that announce or decompress
// to gigabytes, FIFOs, links, crafted databases), each binary gets a fresh copy, and each run is bounded (60 s,
// 6 GB of address space: a run past it fails as out of memory). The table gives, per case and binary: the exit
// status, seconds, peak memory (maximum resident set), the `vmap: error:` lines printed, and what went wrong
// against the goals (a hang, a crash, more than 1 GB, not one error line with exit 2, data lost).
//
//   hostile_bench OLD_VMAP NEW_VMAP [--only SUBSTRING]

#include <signal.h>
#include <sqlite3.h>
#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/testing/hostile_recordings.h"
#include "vmap/testing/recording_writer.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/synthetic_scene.h"

namespace {
namespace fs = std::filesystem;
using vmap::MessageEncoding;
using vmap::testing::BoundedRun;
using vmap::testing::TestMessage;

constexpr uint64_t kMiB = 1 << 20;

std::vector<TestMessage> Frames(MessageEncoding encoding, int count) {
  std::vector<TestMessage> messages;
  for (int i = 0; i < count; ++i) {
    cv::Mat image(64, 96, CV_8UC3);
    cv::RNG(i + 1).fill(image, cv::RNG::UNIFORM, 0, 256);
    const int64_t ns = 1'000'000'000 + i * 100'000'000LL;
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", ns,
                        vmap::testing::SerializeImage(encoding, ns * 1e-9, "cam", image, "bgr8")});
  }
  return messages;
}

void Sql(const fs::path& file, const std::string& schema) {
  sqlite3* db = nullptr;
  sqlite3_open(file.c_str(), &db);
  sqlite3_exec(db, schema.c_str(), nullptr, nullptr, nullptr);
  sqlite3_close(db);
}

const char kTopics[] =
    "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format "
    "TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
    "INSERT INTO topics VALUES (1, '/cam/image_raw', 'sensor_msgs/msg/Image', 'cdr', '');";

int ErrorLines(const std::string& output) {
  int lines = 0;
  for (size_t at = output.find("vmap: error:"); at != std::string::npos; at = output.find("vmap: error:", at + 1)) {
    ++lines;
  }
  return lines;
}

// A map of a rendered drive and a repeat run of it, for the cases that write into a map.
struct Route {
  fs::path teach, repeat, map;
};
Route MakeRoute(const fs::path& dir, const fs::path& binary) {
  vmap::testing::SyntheticOptions options;
  options.num_frames = 40;
  const auto sequence = vmap::testing::RenderSyntheticSequence(options);
  Route route{dir / "teach", dir / "repeat", dir / "map"};
  vmap::testing::WriteImageFolder(sequence, route.teach);
  vmap::testing::WriteImageFolder(sequence, route.repeat);
  vmap::testing::RunBounded(binary, {"build", route.teach.string(), "-o", route.map.string(), "-q"}, 300);
  return route;
}

struct Outcome {
  BoundedRun run;
  double seconds = 0.0;
  std::string problem;  // against the goals; "" when none
};

struct Case {
  std::string name;
  bool bad_input = true;  // expected: exit 2 and one error line; otherwise exit 0
  // Makes the input in `dir` (for `binary`), runs it, and says what was lost or left ("" when nothing).
  std::function<Outcome(const fs::path& dir, const fs::path& binary)> run;
};

// The binary run under prlimit (6 GB of address space); RunBounded measures its own peak memory.
Outcome Timed(const fs::path& binary, const std::vector<std::string>& arguments,
              const std::vector<std::string>& environment = {}) {
  Outcome outcome;
  std::vector<std::string> limited = {"--as=" + std::to_string(6ull << 30), binary.string()};
  limited.insert(limited.end(), arguments.begin(), arguments.end());
  const auto start = std::chrono::steady_clock::now();
  outcome.run = vmap::testing::RunBounded("/usr/bin/prlimit", limited, 60, environment);
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return outcome;
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
  const auto simple = [&](std::string name, std::function<std::vector<std::string>(const fs::path&)> make,
                          bool bad = true) {
    cases.push_back({name, bad, [make](const fs::path& dir, const fs::path& binary) {
                       return Timed(binary, make(dir), {"TMPDIR=" + (dir / "tmp").string()});
                     }});
  };
  // 1, 15: writers of a map.
  cases.push_back(
      {"1. two --add-experience-to at once", false, [](const fs::path& dir, const fs::path& binary) {
         const Route route = MakeRoute(dir, binary);
         Outcome outcome;
         BoundedRun second;
         std::thread other([&] {
           second = vmap::testing::RunBounded(
               binary, {"build", route.repeat.string(), "--add-experience-to", route.map.string()}, 60);
         });
         outcome = Timed(binary, {"build", route.repeat.string(), "--add-experience-to", route.map.string()});
         other.join();
         if (second.status != 0 && outcome.run.status == 0) outcome.run = second;  // report the failure
         std::ifstream in(route.map / "map.json");
         const nlohmann::json doc = nlohmann::json::parse(in, nullptr, false);
         const size_t listed = doc.is_object() && doc.contains("experiences") ? doc["experiences"].size() : 0;
         const BoundedRun localize =
             vmap::testing::RunBounded(binary, {"localize", route.map.string(), route.repeat.string(), "-q"}, 120);
         if (listed != 2 || localize.status != 0) {
           outcome.problem = "data lost: " + std::to_string(listed) + " of 2 experiences listed, localize " + "exits " +
                             std::to_string(localize.status);
         }
         return outcome;
       }});
  cases.push_back(
      {"2. add through a symlinked experiences/", true, [](const fs::path& dir, const fs::path& binary) {
         const Route route = MakeRoute(dir, binary);
         fs::create_directories(dir / "outside");
         fs::create_directory_symlink(dir / "outside", route.map / "experiences");
         Outcome outcome = Timed(binary, {"build", route.repeat.string(), "--add-experience-to", route.map.string()});
         if (!fs::is_empty(dir / "outside")) outcome.problem = "wrote outside the map";
         return outcome;
       }});
  cases.push_back({"15. SIGINT during an add", false, [](const fs::path& dir, const fs::path& binary) {
                     const Route route = MakeRoute(dir, binary);
                     Outcome outcome;
                     {
                       vmap::testing::BackgroundVmap add(
                           {"build", route.repeat.string(), "--add-experience-to", route.map.string()}, dir / "log",
                           binary);
                       // Once it writes (the old add made experiences/ first, the new one its own folder).
                       const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
                       bool writing = false;
                       while (!writing && add.Running() && std::chrono::steady_clock::now() < deadline) {
                         for (const auto& entry : fs::directory_iterator(route.map)) {
                           const std::string name = entry.path().filename().string();
                           writing = writing || name == "experiences" || name.rfind(".experiences", 0) == 0;
                         }
                         std::this_thread::sleep_for(std::chrono::milliseconds(2));
                       }
                       add.Signal(SIGINT);
                       outcome.run.status = add.Wait();
                       outcome.run.output = writing ? "" : "(the add never began writing)";
                     }
                     std::vector<std::string> left;
                     for (const auto& entry : fs::directory_iterator(route.map)) {
                       const std::string name = entry.path().filename().string();
                       if (name == "experiences" || name.rfind(".", 0) == 0) left.push_back(name);
                     }
                     if (!left.empty()) outcome.problem = "left " + left.front() + " in the map";
                     if (outcome.run.status == 128 + SIGINT) outcome.run.status = 0;  // the expected end
                     return outcome;
                   }});
  // 4. FIFOs.
  for (const char* name : {"f.bag", "f.mcap", "f.db3"}) {
    simple(std::string("4. info of a FIFO ") + name, [name](const fs::path& dir) {
      mkfifo((dir / name).c_str(), 0644);
      return std::vector<std::string>{"info", (dir / name).string()};
    });
  }
  simple("4. build of a FIFO .bag", [](const fs::path& dir) {
    mkfifo((dir / "f.bag").c_str(), 0644);
    return std::vector<std::string>{"build", (dir / "f.bag").string(), "-o", (dir / "o").string()};
  });
  simple("4. a FIFO .db3 in a rosbag2 folder", [](const fs::path& dir) {
    fs::create_directories(dir / "rb");
    std::ofstream(dir / "rb/metadata.yaml") << "rosbag2_bagfile_information:\n";
    mkfifo((dir / "rb/rb_0.db3").c_str(), 0644);
    return std::vector<std::string>{"build", (dir / "rb").string(), "-o", (dir / "o").string()};
  });
  simple("4. build FIFO -o o", [](const fs::path& dir) {
    mkfifo((dir / "f").c_str(), 0644);
    return std::vector<std::string>{"build", (dir / "f").string(), "-o", (dir / "o").string()};
  });
  // 5. Hostile sqlite.
  simple("5. messages a recursive VIEW", [](const fs::path& dir) {
    Sql(dir / "r.db3", std::string(kTopics) +
                           "CREATE VIEW messages AS WITH RECURSIVE n(id) AS (SELECT 1 UNION ALL SELECT id + 1 FROM "
                           "n) SELECT id, 1 AS topic_id, id AS timestamp, x'00' AS data FROM n;");
    return std::vector<std::string>{"info", (dir / "r.db3").string()};
  });
  simple("5. messages a zeroblob(9e8) VIEW", [](const fs::path& dir) {
    Sql(dir / "z.db3", std::string(kTopics) +
                           "CREATE VIEW messages AS SELECT 1 AS id, 1 AS topic_id, 0 AS timestamp, "
                           "zeroblob(900000000) AS data;");
    return std::vector<std::string>{"build", (dir / "z.db3").string(), "-o", (dir / "o").string()};
  });
  // 6, 7, 8. Bombs.
  simple("6. MCAP: a zstd chunk of 1.9 GiB", [](const fs::path& dir) {
    std::vector<TestMessage> messages = Frames(MessageEncoding::kCdr, 2);
    std::vector<uint8_t> noise(2 * kMiB);
    cv::randu(cv::Mat(1, static_cast<int>(noise.size()), CV_8U, noise.data()), 0, 256);
    messages.push_back({"/noise", "std_msgs/ByteMultiArray", 1'000'000'000, noise});
    vmap::testing::WriteMcapBomb((dir / "b.mcap").string(), messages, "zstd", 1900 * kMiB);
    return std::vector<std::string>{"build", (dir / "b.mcap").string(), "-o", (dir / "o").string()};
  });
  simple("6. ROS 1 bag: lz4 chunks of 1.9 GiB", [](const fs::path& dir) {
    vmap::testing::Ros1Chunk chunk;
    chunk.messages = Frames(MessageEncoding::kRos1, 1);
    chunk.compression = "lz4";
    chunk.padding = 1900 * kMiB;
    vmap::testing::WriteRos1BagChunks((dir / "b.bag").string(), {chunk, chunk});
    return std::vector<std::string>{"info", (dir / "b.bag").string()};
  });
  simple("6. rosbag2: zstd messages of 300 MiB", [](const fs::path& dir) {
    Sql(dir / "m.db3", std::string(kTopics) +
                           "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp "
                           "INTEGER NOT NULL, data BLOB NOT NULL);");
    const std::string blob = vmap::testing::CompressedWithZeros("zstd", std::string(4, '\0'), 300 * kMiB);
    sqlite3* db = nullptr;
    sqlite3_open((dir / "m.db3").c_str(), &db);
    sqlite3_stmt* insert = nullptr;
    sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (1, ?, ?)", -1, &insert, nullptr);
    for (int i = 0; i < 10; ++i) {
      sqlite3_bind_int64(insert, 1, 1'000'000'000LL + i);
      sqlite3_bind_blob(insert, 2, blob.data(), static_cast<int>(blob.size()), SQLITE_TRANSIENT);
      sqlite3_step(insert);
      sqlite3_reset(insert);
    }
    sqlite3_finalize(insert);
    sqlite3_close(db);
    return std::vector<std::string>{"build", (dir / "m.db3").string(), "-o", (dir / "o").string()};
  });
  simple("7. ROS 1 bag: 100 bz2 chunks of 256 MiB of zeros", [](const fs::path& dir) {
    // 256 MiB in all, records included: as much as a chunk could announce before (more was refused).
    const uint64_t zeros = 256 * kMiB - 64 * 1024;
    const std::string records = vmap::testing::Ros1ChunkRecords(Frames(MessageEncoding::kRos1, 1), zeros);
    vmap::testing::Ros1Chunk chunk;
    chunk.compression = "bz2";
    chunk.stored = vmap::testing::CompressedWithZeros("bz2", records, zeros);
    chunk.announced_size = records.size() + zeros;
    vmap::testing::WriteRos1BagChunks((dir / "z.bag").string(), std::vector<vmap::testing::Ros1Chunk>(100, chunk));
    return std::vector<std::string>{"info", (dir / "z.bag").string()};
  });
  simple("8. rosbag2 .db3.zstd of 1.9 GB", [](const fs::path& dir) {
    vmap::testing::WriteRosbag2((dir / "d").string(), Frames(MessageEncoding::kCdr, 2));
    std::ifstream in(dir / "d/d_0.db3", std::ios::binary);
    const std::string plain((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir / "d/d_0.db3.zstd", std::ios::binary)
        << vmap::testing::CompressedWithZeros("zstd", plain, 1900 * kMiB);
    fs::remove(dir / "d/d_0.db3");
    return std::vector<std::string>{"info", (dir / "d").string()};
  });
  // 9. A member linked from outside.
  simple("9. rosbag2 .db3 a symlink out", [](const fs::path& dir) {
    vmap::testing::WriteRosbag2((dir / "real").string(), Frames(MessageEncoding::kCdr, 4));
    fs::create_directories(dir / "l");
    fs::copy_file(dir / "real/metadata.yaml", dir / "l/metadata.yaml");
    fs::create_symlink(dir / "real/real_0.db3", dir / "l/l_0.db3");
    return std::vector<std::string>{"build", (dir / "l").string(), "-o", (dir / "o").string()};
  });
  // 10. No usable frame.
  simple("10. a topic of 0 messages", [](const fs::path& dir) {
    Sql(dir / "e.db3", std::string(kTopics) +
                           "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp "
                           "INTEGER NOT NULL, data BLOB NOT NULL);");
    return std::vector<std::string>{"build", (dir / "e.db3").string(), "-o", (dir / "o").string()};
  });
  simple("10. --first past the end", [](const fs::path& dir) {
    vmap::testing::WriteMcap((dir / "f.mcap").string(), Frames(MessageEncoding::kCdr, 5), "zstd");
    return std::vector<std::string>{"build", (dir / "f.mcap").string(), "-o", (dir / "o").string(), "--first", "9"};
  });
  // 11. What the reader refuses.
  simple("11. CameraInfo fx NaN", [](const fs::path& dir) {
    std::vector<TestMessage> messages = Frames(MessageEncoding::kCdr, 6);
    messages.insert(messages.begin(),
                    {"/cam/camera_info", "sensor_msgs/CameraInfo", 999'000'000,
                     vmap::testing::SerializeCameraInfo(MessageEncoding::kCdr, 1.0, "cam", {96, 64}, "plumb_bob", {},
                                                        {std::nan(""), 0, 47.5, 0, 80, 31.5, 0, 0, 1})});
    vmap::testing::WriteMcap((dir / "c.mcap").string(), messages, "zstd");
    return std::vector<std::string>{"build", (dir / "c.mcap").string(), "-o", (dir / "o").string()};
  });
  cases.push_back(
      {"11. messages 1 ns apart, then info of the map", false, [](const fs::path& dir, const fs::path& binary) {
         std::vector<TestMessage> fast = Frames(MessageEncoding::kCdr, 8);
         for (size_t i = 0; i < fast.size(); ++i) fast[i].log_time_ns = 1'000'000'000 + static_cast<int64_t>(i);
         vmap::testing::WriteMcap((dir / "f.mcap").string(), fast, "zstd");
         vmap::testing::RunBounded(binary, {"build", (dir / "f.mcap").string(), "-o", (dir / "o").string()}, 60);
         return Timed(binary, {"info", (dir / "o").string()});
       }});
  // 12. OpenCV's refusal of one message.
  cases.push_back({"12. one mono16 image with an odd step", false, [](const fs::path& dir, const fs::path& binary) {
                     std::vector<TestMessage> messages = Frames(MessageEncoding::kCdr, 8);
                     messages[3].data = vmap::testing::SerializeImage(
                         MessageEncoding::kCdr, 1.3, "cam", cv::Mat(64, 96, CV_16UC1, cv::Scalar(9)), "mono16", 1);
                     vmap::testing::WriteMcap((dir / "m.mcap").string(), messages, "zstd");
                     return Timed(binary, {"build", (dir / "m.mcap").string(), "-o", (dir / "o").string()});
                   }});
  // 13. Experiences read by every command.
  for (const char* command : {"info", "route", "report"}) {
    cases.push_back({std::string("13. ") + command + " of a map whose view is ../", true,
                     [command](const fs::path& dir, const fs::path& binary) {
                       const Route route = MakeRoute(dir, binary);
                       std::ifstream in(route.map / "map.json");
                       nlohmann::json doc = nlohmann::json::parse(in);
                       doc["experiences"] = {{{"id", 1},
                                              {"source", "r"},
                                              {"views",
                                               {{{"key", 0},
                                                 {"image", "../teach/000000.png"},
                                                 {"frame_index", 0},
                                                 {"source_index", 0},
                                                 {"timestamp", nullptr},
                                                 {"source_name", "x"},
                                                 {"heading_px", 0.0},
                                                 {"verified", 30}}}}}};
                       std::ofstream(route.map / "map.json") << doc.dump(1);
                       std::vector<std::string> args = {command, route.map.string()};
                       if (std::string(command) == "route") args.insert(args.end(), {"--from", "0", "--to", "1"});
                       return Timed(binary, args);
                     }});
  }
  // 14. map.json of 400,000 small objects.
  cases.push_back({"14. info of a map.json of 400,000 objects", false, [](const fs::path& dir, const fs::path& binary) {
                     const Route route = MakeRoute(dir, binary);
                     std::ifstream in(route.map / "map.json");
                     nlohmann::json doc = nlohmann::json::parse(in);
                     nlohmann::json padding = nlohmann::json::array();
                     for (int i = 0; i < 400000; ++i) padding.push_back({{"a", i}});
                     doc["padding"] = std::move(padding);
                     std::ofstream(route.map / "map.json") << doc.dump();
                     return Timed(binary, {"info", route.map.string()});
                   }});
  // 16, 17, 18.
  cases.push_back({"16. --csv a hard link of a query image", true, [](const fs::path& dir, const fs::path& binary) {
                     const Route route = MakeRoute(dir, binary);
                     fs::create_hard_link(route.repeat / "frame_4.png", dir / "h.png");
                     return Timed(binary, {"localize", route.map.string(), route.repeat.string(), "--csv",
                                           (dir / "h.png").string()});
                   }});
  cases.push_back({"17. report of a run naming key 999", true, [](const fs::path& dir, const fs::path& binary) {
                     const Route route = MakeRoute(dir, binary);
                     vmap::testing::RunBounded(
                         binary,
                         {"localize", route.map.string(), route.repeat.string(), "--json", (dir / "run.json").string()},
                         120);
                     std::ifstream in(dir / "run.json");
                     nlohmann::json run = nlohmann::json::parse(in);
                     run["frames"][0]["key"] = 999;
                     std::ofstream(dir / "run.json") << run.dump(1);
                     return Timed(binary, {"report", (dir / "run.json").string()});
                   }});
  cases.push_back({"18. eval --gt of all-zero poses", true, [](const fs::path& dir, const fs::path& binary) {
                     const Route route = MakeRoute(dir, binary);
                     std::ofstream gt(dir / "gt.txt");
                     for (int i = 0; i < 40; ++i) gt << "0 0 0 0 0 0 0 0 0 0 0 0\n";
                     gt.close();
                     // The camera too: without it the old binary stops at the map's missing camera before reading the
                     // poses.
                     return Timed(binary, {"eval", route.map.string(), "--gt", (dir / "gt.txt").string(), "--gt-format",
                                           "kitti", "--camera", "300,300,160,120"});
                   }});
  return cases;
}

// What went wrong against the goals.
std::string Verdict(const Case& c, const Outcome& o) {
  std::vector<std::string> problems;
  if (o.run.timed_out) problems.push_back("hang (killed at 60 s)");
  if (!o.run.timed_out && o.run.status != 0 && o.run.status != 2) problems.push_back("crash");
  if (o.run.max_rss_bytes > (1L << 30)) problems.push_back("over 1 GB");
  if (o.run.output.find("out of memory") != std::string::npos) problems.push_back("out of memory");
  if (c.bad_input && !o.run.timed_out && (o.run.status != 2 || ErrorLines(o.run.output) != 1)) {
    problems.push_back("not one error line and exit 2");
  }
  if (!c.bad_input && o.run.status != 0 && o.problem.empty()) problems.push_back("refused");
  if (!o.problem.empty()) problems.push_back(o.problem);
  std::string text;
  for (const std::string& p : problems) text += (text.empty() ? "" : "; ") + p;
  return text.empty() ? "ok" : text;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: hostile_bench OLD_VMAP NEW_VMAP [--only SUBSTRING]\n";
    return 2;
  }
  const fs::path binaries[2] = {fs::absolute(argv[1]), fs::absolute(argv[2])};
  const std::string only = argc > 4 && !std::strcmp(argv[3], "--only") ? argv[4] : "";
  char pattern[] = "/tmp/vmap_hostile_XXXXXX";
  const fs::path root = mkdtemp(pattern);
  std::cout << "| case | old: exit, s, peak MB, errors | old verdict | new: exit, s, peak MB, errors | new verdict |\n"
            << "|---|---|---|---|---|\n";
  int index = 0;
  for (const Case& c : Cases()) {
    if (!only.empty() && c.name.find(only) == std::string::npos) continue;
    std::string row = "| " + c.name;
    for (int b = 0; b < 2; ++b) {
      const fs::path dir = root / (std::to_string(index) + (b ? "_new" : "_old"));
      fs::create_directories(dir / "tmp");
      const Outcome o = c.run(dir, binaries[b]);
      char cell[160];
      std::snprintf(cell, sizeof cell, " | %s, %.2f, %ld, %d",
                    o.run.timed_out ? "killed" : std::to_string(o.run.status).c_str(), o.seconds,
                    o.run.max_rss_bytes >> 20, ErrorLines(o.run.output));
      row += cell;
      std::string verdict = Verdict(c, o);
      if (!fs::is_empty(dir / "tmp")) verdict += "; left files in TMPDIR";
      row += " | " + verdict;
      if (getenv("HOSTILE_BENCH_VERBOSE")) std::cerr << c.name << " (" << binaries[b] << "):\n" << o.run.output << "\n";
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
    std::cout << row << " |" << std::endl;
    ++index;
  }
  std::error_code ignored;
  fs::remove_all(root, ignored);
  return 0;
}
