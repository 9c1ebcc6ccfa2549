// The promises of docs/promises.md, each tested on the binary with several inputs:
// 1. vmap replaces only what it can prove it wrote, never its input;
// 2. reading an untrusted map never leaves its folder, reads only what the links reference, checks every field;
// 3. an interrupted run (SIGINT, SIGTERM, SIGKILL) leaves nothing behind;
// 4. every error is vmap's: "vmap: error: ..." naming the file, status 2; bad frames are skipped and counted;
//    file names that are not UTF-8 work;
// 5. every numeric option has a range, checked before any work.

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <functional>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/file_name_encoding.h"
#include "vmap/map/map_io.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::Quote;
using testing::ReadText;
using testing::RunVmap;

namespace {

// The CPU time (user and system) of this process's children that have ended and been waited for.
double ChildrenCpuSeconds() {
  struct rusage usage {};
  getrusage(RUSAGE_CHILDREN, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

void WriteSyntheticInput(const fs::path& directory, int num_frames) {
  testing::SyntheticOptions options;
  options.num_frames = num_frames;
  testing::WriteImageFolder(testing::RenderSyntheticSequence(options), directory);
}

// A small real map at `directory`, built by the binary.
void BuildMap(const fs::path& input, const fs::path& directory, const std::string& extra = "") {
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(input) + " -o " + Quote(directory) + " " + extra, &out), 0) << out;
}

// Names in `directory` that start with `prefix`: temporaries left behind.
std::vector<std::string> EntriesStartingWith(const fs::path& directory, const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

// Waits until `directory` holds an entry starting with `prefix` (the run has started writing).
bool AppearsWithin(const fs::path& directory, const std::string& prefix, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (!EntriesStartingWith(directory, prefix).empty()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

}  // namespace

// ---- 1. Ownership -------------------------------------------------------------------------------------------

TEST(Promises, OutputsVmapCannotProveItsOwnAreNeverReplaced) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  const std::string in = Quote(tmp.path() / "in");
  // The issue's case: a project folder with a map.json that is not a vmap map.
  const fs::path project = tmp.path() / "p";
  fs::create_directories(project / "src");
  fs::create_directories(project / ".git");
  std::ofstream(project / "map.json") << R"({"type":"FeatureCollection"})";
  std::ofstream(project / "src/app.js") << "x";
  // A folder with a sweep.json that is not vmap's, a vmap map given as a sweep's output, a folder with a
  // report.html of its own, a plain file, a link to a vmap map.
  fs::create_directories(tmp.path() / "results");
  std::ofstream(tmp.path() / "results/sweep.json") << "{}";
  std::ofstream(tmp.path() / "results/data.csv") << "1,2";
  BuildMap(tmp.path() / "in", tmp.path() / "real_map");
  fs::create_directories(tmp.path() / "site");
  std::ofstream(tmp.path() / "site/report.html") << "<p>my page</p>";
  std::ofstream(tmp.path() / "notes.txt") << "notes";
  fs::create_directory_symlink(tmp.path() / "real_map", tmp.path() / "map_link");
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {"build " + in + " -o " + Quote(project), "is not a vmap map"},
      {"build " + in + " -o " + Quote(tmp.path() / "results"), "it has no map.json"},
      {"sweep " + in + " --thresholds 0.5 -o " + Quote(tmp.path() / "results"), "not a vmap sweep's"},
      {"sweep " + in + " --thresholds 0.5 -o " + Quote(tmp.path() / "real_map"), "it has no sweep.json"},
      {"sweep " + in + " --thresholds 0.5 --report " + Quote(tmp.path() / "site"), "is not a vmap sweep"},
      {"build " + in + " -o " + Quote(tmp.path() / "notes.txt"), "is not a directory"},
      {"build " + in + " -o " + Quote(tmp.path() / "map_link"), "symbolic link"},
  };
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_NE(out.find("vmap: error: output '"), std::string::npos) << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
  }
  EXPECT_EQ(ReadText(project / "src/app.js"), "x");
  EXPECT_TRUE(fs::is_directory(project / ".git"));
  EXPECT_EQ(ReadText(tmp.path() / "results/data.csv"), "1,2");
  EXPECT_EQ(ReadText(tmp.path() / "site/report.html"), "<p>my page</p>");
  EXPECT_EQ(ReadText(tmp.path() / "notes.txt"), "notes");
  EXPECT_NO_THROW(ReadMap(tmp.path() / "real_map"));
  EXPECT_TRUE(fs::is_symlink(tmp.path() / "map_link"));
  EXPECT_TRUE(EntriesStartingWith(tmp.path(), ".").empty()) << "no temporary left";
}

TEST(Promises, VmapReplacesWhatItWrote) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  const std::string in = Quote(tmp.path() / "in");
  std::string out;
  for (int run = 0; run < 2; ++run) {
    ASSERT_EQ(RunVmap("build " + in + " -o " + Quote(tmp.path() / "m") + " --report", &out), 0) << out;
    ASSERT_EQ(RunVmap("sweep " + in + " --thresholds 0.4,0.8 -o " + Quote(tmp.path() / "s") + " --maps --report " +
                          Quote(tmp.path() / "s"),
                      &out),
              0)
        << out;
    ASSERT_EQ(RunVmap("sweep " + in + " --thresholds 0.4,0.8 --report " + Quote(tmp.path() / "page"), &out), 0) << out;
    ASSERT_EQ(RunVmap("report " + Quote(tmp.path() / "m"), &out), 0) << out;
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "page/report.html"));
  EXPECT_TRUE(fs::exists(tmp.path() / "page/sweep.json")) << "a report folder of its own is a sweep folder";
  EXPECT_TRUE(fs::exists(tmp.path() / "s/report.html"));
  EXPECT_TRUE(EntriesStartingWith(tmp.path(), ".").empty());
  EXPECT_TRUE(EntriesStartingWith(tmp.path() / "m", ".").empty());
}

TEST(Promises, TheInputIsNeverInsideTheOutputNorTheOutputInsideTheInput) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  BuildMap(tmp.path() / "in", tmp.path() / "s");
  BuildMap(tmp.path() / "in", tmp.path() / "old_map");
  fs::create_directory_symlink(tmp.path() / "s/keys", tmp.path() / "keys_link");
  const std::string before = ReadText(tmp.path() / "s/map.json");
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      // The issue's case: `cp -r old_map s; vmap build s/keys -o s`.
      {"build " + Quote(tmp.path() / "s/keys") + " -o " + Quote(tmp.path() / "s"), "is or holds the input"},
      {"build " + Quote(tmp.path() / "keys_link") + " -o " + Quote(tmp.path() / "s"), "is or holds the input"},
      {"build " + Quote(tmp.path() / "s/keys/../keys") + " -o " + Quote(tmp.path() / "s/"), "is or holds the input"},
      {"sweep " + Quote(tmp.path() / "s/keys") + " --thresholds 0.5 -o " + Quote(tmp.path() / "s/keys"),
       "is or holds the input"},
      {"build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "in/map"), "lies inside the input"},
      {"sweep " + Quote(tmp.path() / "in") + " --thresholds 0.5 --report " + Quote(tmp.path() / "in"),
       "is or holds the input"},
  };
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
  }
  EXPECT_EQ(ReadText(tmp.path() / "s/map.json"), before);
  EXPECT_NO_THROW(ReadMap(tmp.path() / "s"));
  EXPECT_FALSE(fs::exists(tmp.path() / "in/map"));
}

// ---- 2. Untrusted maps --------------------------------------------------------------------------------------

TEST(Promises, UntrustedMapsAreRefusedQuicklyWithLittleMemory) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 8);
  BuildMap(tmp.path() / "in", tmp.path() / "good");
  ASSERT_GT(ReadMap(tmp.path() / "good").links.size(), 0u);
  auto variant = [&](const std::string& name, const std::function<void(const fs::path&)>& change) {
    const fs::path dir = tmp.path() / name;
    fs::copy(tmp.path() / "good", dir, fs::copy_options::recursive);
    change(dir);
    return dir;
  };
  struct Case {
    fs::path map;
    std::string expected;
    long max_rss_mb = 400;
  };
  const std::vector<Case> cases = {
      {variant("sparse", [](const fs::path& d) { fs::resize_file(d / kCorrespondencesFileName, 10ull << 30); }),
       "10737418240 bytes"},
      {variant("zero",
               [](const fs::path& d) {
                 fs::remove(d / kCorrespondencesFileName);
                 fs::create_symlink("/dev/zero", d / kCorrespondencesFileName);
               }),
       "resolves outside the map directory"},
      {variant("fifo",
               [](const fs::path& d) {
                 fs::remove(d / kCorrespondencesFileName);
                 mkfifo((d / kCorrespondencesFileName).c_str(), 0600);
               }),
       "is not a regular file"},
      {variant("bad_f",
               [](const fs::path& d) {
                 auto doc = nlohmann::json::parse(ReadText(d / kMapFileName));
                 doc["links"][0]["F"] = {1, 2, 3};
                 std::ofstream(d / kMapFileName) << doc.dump();
               }),
       "'links[0].F' must be null or a list of 9 finite numbers"},
      {variant("huge_number",
               [](const fs::path& d) {
                 std::string text = ReadText(d / kMapFileName);
                 const size_t at = text.find("\"num_frames\": ") + 14;
                 text.replace(at, text.find_first_of(",\n", at) - at, "1e999");
                 std::ofstream(d / kMapFileName) << text;
               }),
       "number too large"},
      {variant("many_values",
               [](const fs::path& d) {
                 // Few bytes a value: 9 million of them in 18 MB, refused by their count before they are held.
                 auto doc = nlohmann::json::parse(ReadText(d / kMapFileName));
                 std::string text = doc.dump();
                 std::string padding = "\"padding\": [0";
                 padding.reserve(18u << 20);
                 for (int i = 0; i < 9000000; ++i) padding += ",0";
                 text.insert(1, padding + "], ");
                 std::ofstream(d / kMapFileName) << text;
               }),
       "holds more than",
       // The values parsed before the count is reached (8,388,608, some 55 bytes each in nlohmann-json): 470 MB
       // measured, where all of them took 1.26 GB and 150 million numbers aborted vmap.
       600},
  };
  for (const Case& c : cases) {
    const std::vector<std::vector<std::string>> commands = {
        {"info", c.map.string()},
        {"report", c.map.string()},
        {"draw", c.map.string(), "--link", "0", "-o", (tmp.path() / "fig.png").string()}};
    for (const std::vector<std::string>& command : commands) {
      const testing::BoundedRun run = testing::RunVmapBounded(command, 120.0);
      EXPECT_EQ(run.status, 2) << c.map << " " << command[0];
      EXPECT_EQ(run.output.find("vmap: error: "), 0u) << run.output;
      EXPECT_NE(run.output.find(c.expected), std::string::npos) << c.map << " " << command[0] << ": " << run.output;
      // CPU time, not wall time: "quickly" is about the work a hostile map can make vmap do, which the load of
      // other processes on a shared machine does not change (wall time doubles when two test jobs share a core).
      EXPECT_LT(run.cpu_seconds, 10.0) << c.map;
      EXPECT_LT(run.max_rss_bytes, c.max_rss_mb << 20)
          << c.map << " " << command[0];  // far below the 10 GB of the sparse file
    }
    EXPECT_FALSE(fs::exists(c.map / "report.html")) << c.map;
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "fig.png"));
}

// The peak memory the test above bounds is the run's own: a test process that grew before (a whole vmap_tests run
// holds what earlier tests left in its heap) does not count in it, as it does in the child posix_spawn starts.
TEST(Promises, TheMemoryOfARunIsItsOwn) {
  std::vector<char> held(768u << 20);
  for (size_t i = 0; i < held.size(); i += 4096) held[i] = static_cast<char>(i);  // resident, not just reserved
  const testing::BoundedRun run = testing::RunVmapBounded({"--version"}, 60.0);
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_GT(run.max_rss_bytes, 0);
  EXPECT_LT(run.max_rss_bytes, 384l << 20) << "this process holds " << (held.size() >> 20) << " MB";
  EXPECT_EQ(run.output.find("vmap-testing-usage"), std::string::npos)
      << run.output;  // the measure's line is not output
}

// ---- 3. Interrupted runs ------------------------------------------------------------------------------------

TEST(Promises, SigintOrSigtermLeaveNothingBehindAndTheOldOutputIntact) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 150);
  BuildMap(tmp.path() / "in", tmp.path() / "m", "--last 9");
  const std::string old_map = ReadText(tmp.path() / "m/map.json");
  struct Case {
    std::vector<std::string> arguments;
    fs::path watched;    // where the run's temporary appears
    std::string prefix;  // its name's start
    int signal_number;
  };
  const std::string in = (tmp.path() / "in").string();
  const std::vector<Case> cases = {
      {{"build", in, "-o", (tmp.path() / "m").string(), "--threads", "1"}, tmp.path(), ".m.partial-", SIGINT},
      {{"sweep", in, "--thresholds", "0.3,0.6,0.9", "-o", (tmp.path() / "s").string(), "--maps", "--threads", "1"},
       tmp.path(),
       ".s.partial-",
       SIGTERM},
      {{"build", in, "-o", (tmp.path() / "m2").string(), "--threads", "1"}, tmp.path(), ".m2.partial-", SIGHUP},
  };
  for (const Case& c : cases) {
    testing::BackgroundVmap process(c.arguments, tmp.path() / "log.txt");
    ASSERT_TRUE(AppearsWithin(c.watched, c.prefix, 30.0)) << c.arguments[0];
    process.Signal(c.signal_number);
    EXPECT_EQ(process.Wait(), 128 + c.signal_number) << ReadText(tmp.path() / "log.txt");
    EXPECT_NE(ReadText(tmp.path() / "log.txt").find("vmap: interrupted"), std::string::npos);
    EXPECT_EQ(EntriesStartingWith(tmp.path(), "."), std::vector<std::string>())
        << c.arguments[0] << " left a temporary";
  }
  EXPECT_EQ(ReadText(tmp.path() / "m/map.json"), old_map) << "the old map is intact";
  EXPECT_FALSE(fs::exists(tmp.path() / "s"));
  EXPECT_FALSE(fs::exists(tmp.path() / "m2"));
}

TEST(Promises, AnInterruptedReportLeavesTheMapAsItWas) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 150);
  BuildMap(tmp.path() / "in", tmp.path() / "m", "--tau 0.99");  // many key images: a report of some length
  ASSERT_GT(ReadMap(tmp.path() / "m").key_images.size(), 20u);
  testing::BackgroundVmap process({"report", (tmp.path() / "m").string()}, tmp.path() / "log.txt");
  ASSERT_TRUE(AppearsWithin(tmp.path() / "m", ".report.partial-", 30.0));
  process.Signal(SIGINT);
  EXPECT_EQ(process.Wait(), 128 + SIGINT) << ReadText(tmp.path() / "log.txt");
  EXPECT_TRUE(EntriesStartingWith(tmp.path() / "m", ".").empty());
  EXPECT_FALSE(fs::exists(tmp.path() / "m/report"));
  EXPECT_FALSE(fs::exists(tmp.path() / "m/report.html"));
  EXPECT_NO_THROW(ReadMap(tmp.path() / "m"));
}

TEST(Promises, TemporariesOfAKilledRunAreRemovedByTheNextRun) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 150);
  testing::BackgroundVmap process(
      {"build", (tmp.path() / "in").string(), "-o", (tmp.path() / "m").string(), "--threads", "1"},
      tmp.path() / "log.txt");
  ASSERT_TRUE(AppearsWithin(tmp.path(), ".m.partial-", 30.0));
  process.Signal(SIGKILL);  // no clean-up is possible
  EXPECT_EQ(process.Wait(), 128 + SIGKILL);
  const std::vector<std::string> left = EntriesStartingWith(tmp.path(), ".m.partial-");
  ASSERT_EQ(left.size(), 1u);
  // A live process's temporary (pid 1 always runs) is not touched.
  fs::create_directories(tmp.path() / ".m.partial-1-77");
  BuildMap(tmp.path() / "in", tmp.path() / "m", "--last 9");
  EXPECT_FALSE(fs::exists(tmp.path() / left[0]));
  EXPECT_TRUE(fs::exists(tmp.path() / ".m.partial-1-77"));
  EXPECT_NO_THROW(ReadMap(tmp.path() / "m"));
}

// ---- 4. Every error is vmap's -------------------------------------------------------------------------------

TEST(Promises, BadFramesAreSkippedWithAWarningAndCounted) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 10);
  cv::imwrite((tmp.path() / "in/frame_3.png").string(), cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(9)));
  cv::imwrite((tmp.path() / "in/frame_6.png").string(), cv::Mat(2, 700, CV_8UC3, cv::Scalar::all(9)));
  std::ofstream(tmp.path() / "in/frame_8.png", std::ios::trunc) << "garbage";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  for (const char* name : {"frame_3.png", "frame_6.png", "frame_8.png"}) {
    EXPECT_NE(out.find(std::string(name) + "': "), std::string::npos) << name << "\n" << out;
  }
  EXPECT_NE(out.find("(3 unusable frames skipped)"), std::string::npos) << out;
  const VisualMap map = ReadMap(tmp.path() / "m");
  EXPECT_EQ(map.skipped_frames, 3);
  EXPECT_EQ(map.num_frames, 7);
  // The first frame bad too: the first good one sets the size.
  cv::imwrite((tmp.path() / "in/frame_1.png").string(), cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(9)));
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  EXPECT_EQ(ReadMap(tmp.path() / "m").skipped_frames, 4);
}

TEST(Promises, FileNamesThatAreNotUtf8Work) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  // Latin-1 names, as an old camera or a Windows share writes them, and a '%'.
  const std::vector<std::string> names = {"caf\xE9_1.png",  "caf\xE9_2.png",  "100%_3.png",
                                          "\xFF\xFE_4.png", "na\xEFve_5.png", "ok_6.png"};
  for (int i = 0; i < 6; ++i)
    fs::rename(tmp.path() / "in" / ("frame_" + std::to_string(i + 1) + ".png"), tmp.path() / "in" / names[i]);
  const fs::path input = tmp.path() / "in\xE9";
  fs::rename(tmp.path() / "in", input);
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(input) + " -o " + Quote(tmp.path() / "m") + " --tau 0.99 --report", &out), 0)
      << out;
  const std::string text = ReadText(tmp.path() / "m/map.json");
  EXPECT_TRUE(IsValidUtf8(text));
  EXPECT_NO_THROW(nlohmann::json::parse(text));
  EXPECT_NE(text.find("caf%E9_1.png"), std::string::npos);
  const VisualMap map = ReadMap(tmp.path() / "m");
  EXPECT_EQ(map.input.path, input.string());
  std::set<std::string> sources;
  for (const KeyImage& k : map.key_images) sources.insert(k.source_name);
  EXPECT_TRUE(sources.count("caf\xE9_1.png")) << "the first frame is a key image";
  for (const std::string& name : sources) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << "not round-tripped: " << name;
  }
  ASSERT_EQ(RunVmap("info " + Quote(tmp.path() / "m"), &out), 0) << out;
  ASSERT_EQ(RunVmap("sweep " + Quote(input) + " --thresholds 0.5 -o " + Quote(tmp.path() / "s"), &out), 0) << out;
  EXPECT_TRUE(IsValidUtf8(ReadText(tmp.path() / "s/sweep.json")));
  ASSERT_EQ(RunVmap("match " + Quote(input / names[0]) + " " + Quote(input / names[1]) + " --json " +
                        Quote(tmp.path() / "match.json"),
                    &out),
            0)
      << out;
  const auto match = nlohmann::json::parse(ReadText(tmp.path() / "match.json"));
  EXPECT_EQ(DecodeFileName(match["image0"]["path"].get<std::string>()), (input / names[0]).string());
}

TEST(Promises, LibraryErrorsBecomeVmapErrorsNamingTheFile) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  BuildMap(tmp.path() / "in", tmp.path() / "m");
  // An image whose header announces 40000 x 40000 pixels: OpenCV refuses to decode it with an exception.
  testing::WritePngHeader(tmp.path() / "big.png", 40000, 40000);
  cv::imwrite((tmp.path() / "tiny.png").string(), cv::Mat(1, 1, CV_8U, cv::Scalar(1)));
  // A key image that does not decode any more (same size header, damaged data).
  fs::copy(tmp.path() / "m", tmp.path() / "damaged", fs::copy_options::recursive);
  const VisualMap map = ReadMap(tmp.path() / "m");
  {
    std::fstream key(tmp.path() / "damaged" / map.key_images[0].image_file,
                     std::ios::in | std::ios::out | std::ios::binary);
    key.seekp(40);
    key.write(std::string(200, '\x55').data(), 200);
  }
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {"match " + Quote(tmp.path() / "big.png") + " " + Quote(tmp.path() / "tiny.png"),
       "image '" + (tmp.path() / "big.png").string() + "' is 40000x40000 (from its header), more than"},
      {"match " + Quote(tmp.path() / "in/frame_1.png") + " " + Quote(tmp.path() / "tiny.png"),
       "tiny.png' is 1x1 (from its header), smaller than 32 pixels"},
      {"report " + Quote(tmp.path() / "damaged"), map.key_images[0].image_file},
      {"draw " + Quote(tmp.path() / "damaged") + " --link 0 -o " + Quote(tmp.path() / "f.png"),
       map.key_images[0].image_file},
      {"draw " + Quote(tmp.path() / "m") + " --link 0 -o " + Quote(tmp.path() / "m/keys/000000.png"),
       "lies inside the map's keys"},
      {"match " + Quote(tmp.path() / "in/frame_1.png") + " " + Quote(tmp.path() / "in/frame_2.png") + " --json " +
           Quote(tmp.path() / "in/frame_2.png"),
       "would overwrite the input image"},
  };
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_EQ(out.rfind("vmap: error: "), out.find("vmap: error: ")) << "one error line\n" << out;
    EXPECT_NE(out.find("vmap: error: "), std::string::npos) << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "damaged/report.html"));
  EXPECT_FALSE(fs::exists(tmp.path() / "f.png"));
}

// ---- 5. Bounded options -------------------------------------------------------------------------------------

TEST(Promises, AbsurdOptionsAreRefusedBeforeAnyWork) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 4);
  BuildMap(tmp.path() / "in", tmp.path() / "m");
  const std::string build = "build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "out") + " ";
  const std::string sweep = "sweep " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "out") + " ";
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {build + "--threads 40000", "--threads must be 0 to 256"},
      {build + "--threads -1", "--threads must be 0 to 256"},
      {build + "--threads abc", "--threads"},
      {build + "--threads 99999999999999", "--threads"},
      {sweep + "--thresholds 0.1:0.9:1e-6", "gives 800001 thresholds, more than 100"},
      {sweep + "--thresholds 0.5,0.5", "gives tau = 0.5 twice"},
      {sweep + "--thresholds nan:1:0.1", "must be start:stop:step"},
      {sweep + "--thresholds 0.1:0.9:inf", "must be start:stop:step"},
      {sweep + "--thresholds 0.501,0.502 --maps", "round to the same map folder 'tau_0.50'"},
      {build + "--resize 100000x100000", "--resize 100000x100000: each side must be 32 to 16384"},
      {build + "--resize 10", "the longest side must be 32 to 16384"},
      {build + "--loftr-size 100000", "--loftr-size 100000 is outside 32 to 4096"},
      {build + "--ratio nan", "--ratio must be in [0, 1]"},
      {build + "--ratio 1.5", "--ratio must be in [0, 1]"},
      {build + "--loftr-threshold nan", "--loftr-threshold must be in [0, 1]"},
      {build + "--loftr-threshold -inf", "--loftr-threshold must be in [0, 1]"},
      {build + "--loftr-threads 100000", "--loftr-threads must be 0 to 256"},
      {build + "--last -5", "--last -5 is not a frame"},
      {build + "--first -1", "--first must be >= 0"},
      {build + "--stride 0", "--stride must be >= 1"},
      {build + "--tau nan", "outside (0, 1]"},
      {build + "--tau inf", "outside (0, 1]"},
      {build + "--threshold nan", "--threshold (verifier, pixels) must be in (0, 100]"},
      {build + "--threshold 1e9", "--threshold (verifier, pixels) must be in (0, 100]"},
      {build + "--confidence nan", "--confidence must be in (0, 1)"},
      {build + "--max-iters 0", "--max-iters must be 1 to 10000000"},
      {build + "--max-iters 2000000000", "--max-iters must be 1 to 10000000"},
      {build + "--seed -3", "--seed must be >= 0"},
      {build + "--orb-features 0", "--orb-features must be 1 to 100000"},
      {build + "--orb-features 100000000", "--orb-features must be 1 to 100000"},
      {build + "--orb-levels 100", "--orb-levels must be 1 to 32"},
      {build + "--orb-scale-factor nan", "--orb-scale-factor must be in (1, 4]"},
      {build + "--orb-fast-threshold 300", "--orb-fast-threshold must be 1 to 255"},
      {build + "--orb-edge-threshold -1", "--orb-edge-threshold must be 0 to 1000"},
      {build + "--frobnicate", "--frobnicate"},
      {"report " + Quote(tmp.path() / "m") + " --thumbnail-width 1", "--thumbnail-width"},
      {"draw " + Quote(tmp.path() / "m") + " --link 0 -o " + Quote(tmp.path() / "out.png") + " --width 5",
       "--width is 5; use 0"},
      {"build", "input is required"},
  };
  for (const Case& c : cases) {
    std::string out;
    const double cpu_before = ChildrenCpuSeconds();
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_EQ(out.find("vmap: error: "), 0u) << c.arguments << "\n" << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
    EXPECT_FALSE(fs::exists(tmp.path() / "out")) << c.arguments;
    EXPECT_FALSE(fs::exists(tmp.path() / "out.png")) << c.arguments;
    // CPU time, not wall time, as for the untrusted maps: a loaded machine stretches the wall time, not the work.
    EXPECT_LT(ChildrenCpuSeconds() - cpu_before, 10.0) << c.arguments;
  }
  EXPECT_TRUE(EntriesStartingWith(tmp.path(), ".").empty());
  // The limits themselves are accepted, and so is --last -1 ("to the end").
  std::string out;
  EXPECT_EQ(RunVmap(build + "--threads 256 --last -1 --ratio 1 --orb-levels 32 --resize 32x32", &out), 0) << out;
  // --help and --version are not errors.
  EXPECT_EQ(RunVmap("--help", &out), 0) << out;
  EXPECT_EQ(RunVmap("build --help", &out), 0) << out;
  EXPECT_NE(out.find("--threads"), std::string::npos);
  EXPECT_EQ(RunVmap("--version", &out), 0) << out;
  EXPECT_EQ(out.rfind("vmap ", 0), 0u) << out;
}

}  // namespace vmap
