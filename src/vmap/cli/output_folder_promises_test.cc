// The promises of docs/promises.md for the output folders (maps, sweeps, reports), each tested on the binary with
// several inputs:
// 1. vmap replaces only what it can prove it wrote, never its input;
// 3. an interrupted run (SIGINT, SIGTERM, SIGKILL) leaves nothing behind.

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>

#include <chrono>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "vmap/map/map_io.h"
#include "vmap/pipelines/localize_odometry.h"
#include "vmap/testing/promises_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::BuildMapWithBinary;
using testing::EntriesStartingWith;
using testing::Quote;
using testing::ReadText;
using testing::RunVmap;
using testing::WriteSyntheticInput;

namespace {

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
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "real_map");
  fs::create_directories(tmp.path() / "site");
  std::ofstream(tmp.path() / "site/report.html") << "<p>my page</p>";
  std::ofstream(tmp.path() / "notes.txt") << "notes";
  fs::create_directory_symlink(tmp.path() / "real_map", tmp.path() / "map_link");
  // A run.json of `vmap localize --json` among a user's files, and a localization report the user added a file to.
  std::string log;
  const std::string localize = "localize " + Quote(tmp.path() / "real_map") + " " + in;
  fs::create_directories(tmp.path() / "thesis");
  ASSERT_EQ(RunVmap(localize + " --json " + Quote(tmp.path() / "thesis/run.json"), &log), 0) << log;
  std::ofstream(tmp.path() / "thesis/thesis.tex") << "draft";
  ASSERT_EQ(RunVmap(localize + " --report " + Quote(tmp.path() / "page"), &log), 0) << log;
  ASSERT_EQ(RunVmap(localize + " --report " + Quote(tmp.path() / "added"), &log), 0) << log;
  std::ofstream(tmp.path() / "added/notes.txt") << "mine";
  // Reports the user added to inside their report/ folder: a file, a folder, a file among the frames. The report
  // replaces report/ whole, and deleted them without a word.
  for (const char* copy : {"inner_file", "inner_folder", "inner_frame"}) {
    fs::copy(tmp.path() / "page", tmp.path() / copy, fs::copy_options::recursive);
  }
  std::ofstream(tmp.path() / "inner_file/report/notes.txt") << "inner notes";
  fs::create_directories(tmp.path() / "inner_folder/report/mine");
  std::ofstream(tmp.path() / "inner_folder/report/mine/figure.txt") << "figure";
  fs::create_directories(tmp.path() / "inner_frame/report/frames");
  std::ofstream(tmp.path() / "inner_frame/report/frames/annotated.png") << "annotated";
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
      {localize + " --report " + Quote(tmp.path() / "thesis"), "it has no report.html"},
      {"report " + Quote(tmp.path() / "thesis/run.json") + " -o " + Quote(tmp.path() / "thesis"), "holds the input"},
      {localize + " --report " + Quote(tmp.path() / "added"), "it holds 'notes.txt'"},
      {localize + " --report " + Quote(tmp.path() / "inner_file"), "it holds 'report/notes.txt'"},
      {"report " + Quote(tmp.path() / "page/run.json") + " -o " + Quote(tmp.path() / "inner_folder"),
       "it holds 'report/mine'"},
      {localize + " --report " + Quote(tmp.path() / "inner_frame"), "it holds 'report/frames/annotated.png'"},
      {"report " + Quote(tmp.path() / "page/run.json") + " -o " + Quote(tmp.path() / "page"), "page/run.json"},
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
  EXPECT_EQ(ReadText(tmp.path() / "thesis/thesis.tex"), "draft");
  EXPECT_EQ(ReadText(tmp.path() / "added/notes.txt"), "mine");
  EXPECT_EQ(ReadText(tmp.path() / "inner_file/report/notes.txt"), "inner notes");
  EXPECT_EQ(ReadText(tmp.path() / "inner_folder/report/mine/figure.txt"), "figure");
  EXPECT_EQ(ReadText(tmp.path() / "inner_frame/report/frames/annotated.png"), "annotated");
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
    EXPECT_NE(out.find("report written to " + (tmp.path() / "page").string()), std::string::npos) << out;
    ASSERT_EQ(RunVmap("report " + Quote(tmp.path() / "m"), &out), 0) << out;
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "page/report.html"));
  EXPECT_TRUE(fs::exists(tmp.path() / "page/sweep.json")) << "a report folder of its own is a sweep folder";
  EXPECT_TRUE(fs::exists(tmp.path() / "s/report.html"));
  EXPECT_TRUE(EntriesStartingWith(tmp.path(), ".").empty());
  EXPECT_TRUE(EntriesStartingWith(tmp.path() / "m", ".").empty());
}

// A rebuilt map keeps what its folder held besides the map: the teach odometry a host put there, a user's notes, a
// run's outputs. They were removed without a word, and the taught speeds and turns with the teach odometry.
TEST(Promises, ARebuiltMapKeepsWhatItsFolderHeldBesidesTheMap) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  const std::string build = "build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m");
  std::string out;
  ASSERT_EQ(RunVmap(build + " --report", &out), 0) << out;
  std::ofstream(tmp.path() / "m" / kTeachOdometryFileName) << "time,x,y,yaw\n0,0,0,0\n";
  std::ofstream(tmp.path() / "m" / "notes.txt") << "taught on Monday";
  ASSERT_EQ(RunVmap(build + " --tau 0.6", &out), 0) << out;
  EXPECT_NE(out.find("replaced a vmap map and keeps what it held besides its own files: notes.txt, teach_odometry.csv"),
            std::string::npos)
      << out;
  EXPECT_EQ(ReadText(tmp.path() / "m" / "notes.txt"), "taught on Monday");
  EXPECT_EQ(ReadText(tmp.path() / "m" / kTeachOdometryFileName), "time,x,y,yaw\n0,0,0,0\n");
  EXPECT_FALSE(fs::exists(tmp.path() / "m" / "report.html")) << "the old map's report is the old map's";
  EXPECT_TRUE(EntriesStartingWith(tmp.path(), ".").empty());
}

TEST(Promises, TheInputIsNeverInsideTheOutputNorTheOutputInsideTheInput) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "s");
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "old_map");
  fs::create_directory_symlink(tmp.path() / "s/keys", tmp.path() / "keys_link");
  // A folder of links to the map's own key images, as `cp -s` or a dataset tool makes one.
  fs::create_directories(tmp.path() / "linked/images");
  for (const fs::directory_entry& key : fs::directory_iterator(tmp.path() / "s/keys")) {
    fs::create_symlink(key.path(), tmp.path() / "linked/images" / key.path().filename());
  }
  const std::string before = ReadText(tmp.path() / "s/map.json");
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      // The issue's case: `cp -r old_map s; vmap build s/keys -o s`.
      {"build " + Quote(tmp.path() / "s/keys") + " -o " + Quote(tmp.path() / "s"), "is or holds the input"},
      {"build " + Quote(tmp.path() / "keys_link") + " -o " + Quote(tmp.path() / "s"), "is or holds the input"},
      {"build " + Quote(tmp.path() / "s/keys/../keys") + " -o " + Quote(tmp.path() / "s/"), "is or holds the input"},
      {"build " + Quote(tmp.path() / "linked") + " -o " + Quote(tmp.path() / "s"), "is or holds the input"},
      {"sweep " + Quote(tmp.path() / "linked") + " --thresholds 0.5 --maps -o " + Quote(tmp.path() / "s/keys"),
       "is or holds the input"},
      {"sweep " + Quote(tmp.path() / "s/keys") + " --thresholds 0.5 -o " + Quote(tmp.path() / "s/keys"),
       "is or holds the input"},
      {"build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "in/map"), "lies inside the input"},
      {"sweep " + Quote(tmp.path() / "in") + " --thresholds 0.5 --report " + Quote(tmp.path() / "in"),
       "is or holds the input"},
      // The files a build reads besides its recording: a camera mask or a calibration kept in the old map's folder.
      {"build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "s") + " --camera-mask " +
           Quote(tmp.path() / "s/mask.png"),
       "is or holds the input"},
      {"build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "s") + " --camera " +
           Quote(tmp.path() / "s/camera.yaml"),
       "is or holds the input"},
  };
  std::ofstream(tmp.path() / "s/mask.png") << "the user's mask";
  std::ofstream(tmp.path() / "s/camera.yaml") << "the user's calibration";
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
  }
  EXPECT_EQ(ReadText(tmp.path() / "s/map.json"), before);
  EXPECT_NO_THROW(ReadMap(tmp.path() / "s"));
  EXPECT_FALSE(fs::exists(tmp.path() / "in/map"));
  EXPECT_EQ(ReadText(tmp.path() / "s/mask.png"), "the user's mask");
  EXPECT_EQ(ReadText(tmp.path() / "s/camera.yaml"), "the user's calibration");
}

// ---- 3. Interrupted runs ------------------------------------------------------------------------------------

TEST(Promises, SigintOrSigtermLeaveNothingBehindAndTheOldOutputIntact) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 150);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "m", "--last 9");
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

// A write that fails part way: the file size limit stands in for a full disk (both fail write(2) in mid-file, and
// cv::imwrite once reported a PNG cut short by a full disk as written). The build fails naming the reason, and the
// old map stays as it was, whether a key image is copied from the input or encoded (--resize).
TEST(Promises, AWriteThatFailsPartWayKeepsTheOldMapAndSaysWhy) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 12);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "m", "--last 5");
  const std::string old_map = ReadText(tmp.path() / "m/map.json");
  struct rlimit old_limit {};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  // Left at its default, as a shell leaves it: vmap ignores it itself, so that write(2) fails instead of the signal
  // killing it with its temporaries left.
  const auto old_handler = signal(SIGXFSZ, SIG_DFL);
  struct rlimit small = old_limit;
  small.rlim_cur = 2048;
  std::vector<std::string> outputs;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  for (const char* extra : {"", " --resize 300"}) {
    std::string out;
    const int status = RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m") + extra, &out);
    outputs.push_back(std::to_string(status) + " " + out);
  }
  setrlimit(RLIMIT_FSIZE, &old_limit);
  signal(SIGXFSZ, old_handler);
  for (const std::string& output : outputs) {
    EXPECT_EQ(output.rfind("2 ", 0), 0u) << output;
    // Named where the user will look for it, not in the hidden folder it was written into.
    EXPECT_NE(output.find("cannot write key image '" + (tmp.path() / "m/keys/").string()), std::string::npos) << output;
    EXPECT_EQ(output.find(".m.partial-"), std::string::npos) << output;
    EXPECT_NE(output.find("(File too large)"), std::string::npos) << output;
    EXPECT_EQ(output.find("libpng"), std::string::npos) << output;
  }
  EXPECT_EQ(ReadText(tmp.path() / "m/map.json"), old_map) << "the old map is intact";
  EXPECT_EQ(EntriesStartingWith(tmp.path(), "."), std::vector<std::string>()) << "a temporary was left";
}

TEST(Promises, AnInterruptedReportLeavesTheMapAsItWas) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 150);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "m", "--tau 0.99");  // many key images: a report of some length
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

// A report whose page may not be replaced (here a link to the user's own page) is refused before report/ is: a
// refusal writes nothing.
TEST(Promises, AReportRefusedForItsPageLeavesItsImagesAsTheyWere) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 8);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "m", "--report");
  std::ofstream(tmp.path() / "m/report/marker") << "old";
  std::ofstream(tmp.path() / "mine.html") << "<p>mine</p>";
  fs::remove(tmp.path() / "m/report.html");
  fs::create_symlink(tmp.path() / "mine.html", tmp.path() / "m/report.html");
  std::string out;
  EXPECT_EQ(RunVmap("report " + Quote(tmp.path() / "m"), &out), 2) << out;
  EXPECT_NE(out.find("report.html"), std::string::npos) << out;
  EXPECT_NE(out.find("symbolic link"), std::string::npos) << out;
  EXPECT_EQ(ReadText(tmp.path() / "m/report/marker"), "old");
  EXPECT_EQ(ReadText(tmp.path() / "mine.html"), "<p>mine</p>");
  EXPECT_TRUE(EntriesStartingWith(tmp.path() / "m", ".").empty());
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
  // Nor one whose pid runs nowhere here (beyond Linux's largest pid) but that its owner holds locked, as a vmap in
  // another container sharing the folder does; the same unlocked is a killed process's.
  const fs::path elsewhere = tmp.path() / ".m.partial-4194305-1", killed = tmp.path() / ".m.partial-4194305-2";
  fs::create_directories(elsewhere);
  fs::create_directories(killed);
  const int held = open(elsewhere.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_EQ(flock(held, LOCK_SH), 0);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "m", "--last 9");
  close(held);
  EXPECT_FALSE(fs::exists(tmp.path() / left[0]));
  EXPECT_TRUE(fs::exists(tmp.path() / ".m.partial-1-77"));
  EXPECT_TRUE(fs::exists(elsewhere));
  EXPECT_FALSE(fs::exists(killed));
  EXPECT_NO_THROW(ReadMap(tmp.path() / "m"));
}

}  // namespace vmap
