// The promises of docs/promises.md for the single-file outputs (--csv, --json, -o FILE) and the files a user
// names (ground truth, runs, queries), each tested on the binary: a refusal is one "vmap: error:" line with
// status 2, names the file, and leaves every input as it was.

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/map/map_io.h"
#include "vmap/testing/promises_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::CliResult;
using testing::Quote;
using testing::ReadText;
using testing::RunVmap;

namespace {

// A small map built by the binary from a synthetic image folder at `directory`/in, into `directory`/m.
void BuildMap(const fs::path& directory) {
  testing::SyntheticOptions options;
  options.num_frames = 8;
  testing::WriteImageFolder(testing::RenderSyntheticSequence(options), directory / "in");
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(directory / "in") + " -o " + Quote(directory / "m"), &out), 0) << out;
}

// Every regular file under `directory` (symbolic links not followed) with a digest of its bytes.
std::map<std::string, size_t> Snapshot(const fs::path& directory) {
  std::map<std::string, size_t> files;
  for (const auto& entry : fs::recursive_directory_iterator(directory)) {
    if (entry.is_regular_file() && !entry.is_symlink()) {
      files[entry.path().string()] = std::hash<std::string>()(ReadText(entry.path()));
    }
  }
  return files;
}

struct Case {
  std::string arguments;
  std::string expected;  // in the error line
};

void ExpectRefused(const std::vector<Case>& cases, const fs::path& watched) {
  const auto before = Snapshot(watched);
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    const size_t error = out.find("vmap: error: ");
    EXPECT_NE(error, std::string::npos) << c.arguments << "\n" << out;
    EXPECT_NE(out.find(c.expected, error), std::string::npos)
        << c.arguments << "\n  expected: " << c.expected << "\n  got: " << out;
    EXPECT_EQ(out.find("please report it"), std::string::npos) << out;
  }
  EXPECT_EQ(Snapshot(watched), before) << "an input changed";
}

}  // namespace

TEST(OutputPromises, SingleFileOutputsNeverReplaceAnInputOrASpecialFile) {
  testing::ScopedTempDir tmp;
  BuildMap(tmp.path());
  const fs::path m = tmp.path() / "m", in = tmp.path() / "in";
  const std::string map = Quote(m), query = Quote(in / "frame_1.png");
  std::ofstream(tmp.path() / "gt.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n";
  std::ofstream(tmp.path() / "target.csv") << "keep me";
  std::ofstream(tmp.path() / "calib.txt") << "500 500 16 12\n";
  fs::copy_file(in / "frame_1.png", tmp.path() / "mask.png");
  fs::create_symlink(tmp.path() / "target.csv", tmp.path() / "link.csv");
  fs::create_symlink(tmp.path() / "target.png", tmp.path() / "link.png");
  std::ofstream(tmp.path() / "readonly.csv") << "keep me too";
  fs::permissions(tmp.path() / "readonly.csv", fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  ASSERT_EQ(mkfifo((tmp.path() / "fifo.csv").c_str(), 0600), 0);
  fs::create_hard_link(in / "frame_2.png", tmp.path() / "hardlink.png");
  fs::create_directories(m / "report/links");  // as `vmap report` writes it
  const std::string localize = "localize " + map + " " + query;
  ExpectRefused(
      {
          {localize + " --csv " + query, "--csv '" + (in / "frame_1.png").string() + "' would overwrite the query"},
          {localize + " --csv " + Quote(m / kMapFileName), "would overwrite the map's map.json"},
          {localize + " --csv " + Quote(m / "keys/000000.png"), "lies inside the map's keys"},
          {localize + " --json " + Quote(m / kCorrespondencesFileName),
           "would overwrite the map's correspondences.bin"},
          {localize + " --json " + Quote(m / "keys/../map.json"), "would overwrite the map's map.json"},
          {localize + " --json " + Quote(m / "localization_cache.bin"), "the map's localization_cache.bin"},
          {localize + " --csv " + Quote(tmp.path() / "link.csv"), "is a symbolic link"},
          {localize + " --csv " + Quote(tmp.path() / "readonly.csv"), "is read-only"},
          {localize + " --csv " + Quote(tmp.path() / "fifo.csv"), "is not a regular file"},
          {localize + " --csv /dev/null", "--csv '/dev/null' is not a regular file"},
          {localize + " --csv /dev/full", "is not a regular file"},
          {localize + " --csv " + Quote(tmp.path() / "a.csv") + " --json " + Quote(tmp.path() / "a.csv"),
           "is also the output of --csv"},
          {localize + " --csv " + Quote(tmp.path() / "nowhere/a.csv"), "does not exist; create it first"},
          {"localize " + map + " " + Quote(in) + " --csv " + Quote(in / "new.csv"), "lies inside the query"},
          {localize + " --report " + Quote(tmp.path()), "is or holds the input"},
          {localize + " --report " + Quote(in), "is or holds the input"},
          {"route " + map + " --json " + Quote(m / kMapFileName), "would overwrite the map's map.json"},
          {"route " + map + " --json /dev/null", "is not a regular file"},
          {"eval " + map + " --gt " + Quote(tmp.path() / "gt.txt") + " --json " + Quote(tmp.path() / "gt.txt"),
           "would overwrite the ground truth"},
          {"eval " + map + " --no-save --json " + Quote(m / "eval.json"), "is the map's own evaluation"},
          {"match " + query + " " + Quote(in / "frame_2.png") + " --json " + Quote(tmp.path() / "hardlink.png"),
           "would overwrite the input image"},
          {"draw " + map + " --link 0 -o " + Quote(m / "keys/000001.png"), "lies inside the map's keys"},
          {"draw " + map + " --link 0 -o " + Quote(tmp.path() / "link.png"), "is a symbolic link"},
          // The map's other files, whether this map has them or not, and the files an option names.
          {localize + " --csv " + Quote(m / "camera_mask.png"), "would overwrite the map's camera_mask.png"},
          {localize + " --csv " + Quote(m / "teach_odometry.csv"), "would overwrite the map's teach_odometry.csv"},
          {localize + " --json " + Quote(m / "experiences"), "the map's experiences"},
          {"draw " + map + " --link 0 -o " + Quote(m / "camera_mask.png"), "the map's camera_mask.png"},
          // What `vmap report` replaces in report/; a user's own figure beside it is allowed (below).
          {"draw " + map + " --link 0 -o " + Quote(m / "report/links/mine.png"), "the map's report/links"},
          {localize + " --camera " + Quote(tmp.path() / "calib.txt") + " --csv " + Quote(tmp.path() / "calib.txt"),
           "would overwrite the camera file"},
          {"match " + query + " " + Quote(in / "frame_2.png") + " --camera " + Quote(tmp.path() / "calib.txt") +
               " --json " + Quote(tmp.path() / "calib.txt"),
           "would overwrite the camera file"},
          {"match " + query + " " + Quote(in / "frame_2.png") + " --camera-mask " + Quote(tmp.path() / "mask.png") +
               " --json " + Quote(tmp.path() / "mask.png"),
           "would overwrite a file the matcher reads"},
      },
      tmp.path());
  EXPECT_EQ(ReadText(tmp.path() / "target.csv"), "keep me");
  EXPECT_TRUE(fs::is_fifo(tmp.path() / "fifo.csv"));
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_FALSE(fs::exists(tmp.path() / "a.csv"));
  // report.md invites a user's files into the map's report/, which no command reads: an exported figure is written.
  std::string out;
  EXPECT_EQ(RunVmap("draw " + map + " --link 0 -o " + Quote(m / "report/link0.png"), &out), 0) << out;
  EXPECT_FALSE(cv::imread((m / "report/link0.png").string()).empty());
}

TEST(OutputPromises, UserNamedFilesAreReadOnlyWhenRegularAndBounded) {
  testing::ScopedTempDir tmp;
  BuildMap(tmp.path());
  const std::string map = Quote(tmp.path() / "m");
  ASSERT_EQ(mkfifo((tmp.path() / "fifo").c_str(), 0600), 0);
  ASSERT_EQ(mkfifo((tmp.path() / "fifo.json").c_str(), 0600), 0);
  std::ofstream(tmp.path() / "sparse.txt").close();
  fs::resize_file(tmp.path() / "sparse.txt", 5ull << 30);
  ExpectRefused(
      {
          {"eval " + map + " --gt " + Quote(tmp.path() / "fifo"), "is not a regular file"},
          {"localize " + map + " " + Quote(tmp.path() / "fifo"), "is neither a file nor a folder"},
          {"eval " + map + " --gt /dev/zero", "is not a regular file"},
          {"eval " + map + " --gt " + Quote(tmp.path() / "sparse.txt"), "is larger than 256 MB"},
          {"report " + Quote(tmp.path() / "fifo.json"), "not a regular file"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --odometry " + Quote(tmp.path() / "fifo"),
           "odometry CSV '" + (tmp.path() / "fifo").string() + "' is not a regular file"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --teach-odometry /dev/zero",
           "odometry CSV '/dev/zero' is not a regular file"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --teach-odometry " + Quote(tmp.path() / "sparse.txt"),
           "is larger than 1024 MB"},
          {"simulate --trials 1 --route /dev/zero", "route CSV '/dev/zero' is not a regular file"},
          {"simulate --trials 1 --route " + Quote(tmp.path() / "fifo"), "is not a regular file"},
          {"simulate --trials 1 --route " + Quote(tmp.path() / "sparse.txt"), "is larger than 16 MB"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --camera /dev/zero",
           "calibration file '/dev/zero' is not a regular file"},
          {"match " + Quote(tmp.path() / "fifo") + " " + Quote(tmp.path() / "in/frame_1.png"), "is not a regular file"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --from -2", "--from"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --first ''", "--first is empty"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --csv=", "--csv is empty"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --report ''", "--report is empty"},
          {"localize " + map + " " + Quote(tmp.path() / "in") + " --threads ''", "--threads is empty"},
          {"route " + map + " --from ''", "--from is empty"},
          {"eval " + map + " --gt ''", "--gt is empty"},
          {"eval " + map + " --camera nan,1,2,3", "--camera"},
          {"info ''", "is empty"},
      },
      tmp.path() / "m");
}

// A cache that is a symbolic link out of the map folder is neither read nor replaced: the run computes the key
// images' features and goes on.
TEST(OutputPromises, TheKeyImageCacheStaysInsideTheMap) {
  testing::ScopedTempDir tmp;
  BuildMap(tmp.path());
  std::ofstream(tmp.path() / "elsewhere.bin") << "not a cache";
  fs::create_symlink(tmp.path() / "elsewhere.bin", tmp.path() / "m/localization_cache.bin");
  std::string out;
  EXPECT_EQ(RunVmap("localize " + Quote(tmp.path() / "m") + " " + Quote(tmp.path() / "in/frame_3.png"), &out), 0)
      << out;
  EXPECT_EQ(ReadText(tmp.path() / "elsewhere.bin"), "not a cache");
  EXPECT_TRUE(fs::is_symlink(tmp.path() / "m/localization_cache.bin"));
}

// The report of a single image is made from the frame the run kept; `vmap report` of its run.json works too.
TEST(OutputPromises, ReportsOfASingleImageNeedNotReadItAgain) {
  testing::ScopedTempDir tmp;
  BuildMap(tmp.path());
  const fs::path image = tmp.path() / "query.png";
  fs::copy_file(tmp.path() / "in/frame_3.png", image);
  std::string out;
  ASSERT_EQ(RunVmap("localize " + Quote(tmp.path() / "m") + " " + Quote(image) + " --report " +
                        Quote(tmp.path() / "r") + " --json " + Quote(tmp.path() / "run.json"),
                    &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(tmp.path() / "r/report.html"));
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path() / "r/report/frames"), fs::directory_iterator()), 1);
  fs::remove(image);  // gone: the report of the run file must not need it
  ASSERT_EQ(RunVmap("report " + Quote(tmp.path() / "run.json") + " -o " + Quote(tmp.path() / "r2"), &out), 0) << out;
  EXPECT_NE(ReadText(tmp.path() / "r2/report.html").find("No frames to show"), std::string::npos);
}

// A run made with relative paths is reported from any folder: its map and query were looked for from where
// `vmap report` ran and beside the run only, and the report said to build a map that exists.
TEST(OutputPromises, ARunsReportIsMadeFromAnyFolder) {
  testing::ScopedTempDir tmp;
  BuildMap(tmp.path());
  fs::create_directories(tmp.path() / "work" / "reps");
  const std::string in_work = "cd " + Quote(tmp.path() / "work") + " &&";
  CliResult run = RunVmap("localize ../m ../in/frame_3.png --report reps/r1", in_work);
  ASSERT_EQ(run.status, 0) << run.output;
  CliResult report = RunVmap("report r1/run.json -o again", "cd " + Quote(tmp.path() / "work" / "reps") + " &&");
  ASSERT_EQ(report.status, 0) << report.output;
  EXPECT_TRUE(fs::exists(tmp.path() / "work" / "reps" / "again" / "report.html"));
  EXPECT_NE(ReadText(tmp.path() / "work" / "reps" / "again" / "report.html").find("../m"), std::string::npos)
      << "the map named as the run named it";
}

// Names that are not UTF-8 are percent-encoded in every JSON vmap writes, as in map.json.
TEST(OutputPromises, JsonOutputsTakeNamesThatAreNotUtf8) {
  testing::ScopedTempDir tmp;
  BuildMap(tmp.path());
  const fs::path odd = tmp.path() / "caf\xE9";
  fs::create_directory(odd);
  fs::copy_file(tmp.path() / "in/frame_2.png", odd / "\xFF_2.png");
  fs::copy_file(tmp.path() / "in/frame_4.png", odd / "\xFF_4.png");
  fs::rename(tmp.path() / "m", tmp.path() / "m\xE9");
  const std::string map = Quote(tmp.path() / "m\xE9");
  std::string out;
  ASSERT_EQ(RunVmap("localize " + map + " " + Quote(odd) + " --json " + Quote(tmp.path() / "run.json") + " --csv " +
                        Quote(tmp.path() / "run.csv"),
                    &out),
            0)
      << out;
  const nlohmann::json run = nlohmann::json::parse(ReadText(tmp.path() / "run.json"));
  EXPECT_NE(run["query"]["path"].get<std::string>().find("caf%E9"), std::string::npos);
  EXPECT_NE(run["frames"][0]["source_name"].get<std::string>().find("%FF_2.png"), std::string::npos);
  // The CSV names the frames as the JSON does (it once wrote the raw bytes, which a UTF-8 reader refuses).
  const std::string csv = ReadText(tmp.path() / "run.csv");
  EXPECT_NE(csv.find(",%FF_2.png,"), std::string::npos) << csv;
  EXPECT_EQ(csv.find('\xFF'), std::string::npos);
  ASSERT_EQ(RunVmap("route " + map + " --json " + Quote(tmp.path() / "route.json"), &out), 0) << out;
  EXPECT_NE(ReadText(tmp.path() / "route.json").find("m%E9"), std::string::npos);
  ASSERT_EQ(RunVmap("report " + Quote(tmp.path() / "run.json") + " -o " + Quote(tmp.path() / "r"), &out), 0) << out;
}

// A localize whose outputs cannot all be written (the file size limit stands in for a full disk) puts none in place:
// the outputs of the run before stay as they were, though the ones written first fitted.
TEST(OutputPromises, ALocalizeThatCannotWriteAllItsOutputsReplacesNone) {
  testing::ScopedTempDir tmp;
  BuildMap(tmp.path());
  const fs::path csv = tmp.path() / "run.csv";
  const fs::path json = tmp.path() / "run.json";
  const fs::path report = tmp.path() / "r";
  const std::string localize = "localize " + Quote(tmp.path() / "m") + " " + Quote(tmp.path() / "in") + " --csv " +
                               Quote(csv) + " --json " + Quote(json);
  std::string out;
  ASSERT_EQ(RunVmap(localize + " --report " + Quote(report), &out), 0) << out;
  uintmax_t largest_image = 0;
  for (const auto& entry : fs::recursive_directory_iterator(report)) {
    if (entry.is_regular_file() && entry.path().extension() == ".jpg")
      largest_image = std::max(largest_image, entry.file_size());
  }
  const uintmax_t csv_size = fs::file_size(csv);
  const uintmax_t json_size = fs::file_size(json);
  ASSERT_LT(csv_size, json_size);
  ASSERT_LT(json_size, largest_image) << "the report's images must be the largest files for this test";
  struct stat report_before {};
  ASSERT_EQ(stat((report / "report.html").c_str(), &report_before), 0);

  struct Case {
    std::string extra;
    uintmax_t limit;  // bytes a file may have: the first outputs fit, a later one does not
  };
  for (const Case& c : {Case{"", (csv_size + json_size) / 2}, Case{" --report " + Quote(report), json_size + 1}}) {
    std::ofstream(csv) << "old\n";
    std::ofstream(json) << "old\n";
    struct rlimit old_limit {};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
    const auto old_handler = signal(SIGXFSZ, SIG_DFL);  // as a shell leaves it: vmap ignores it itself
    struct rlimit small = old_limit;
    small.rlim_cur = c.limit;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
    const int status = RunVmap(localize + c.extra, &out);
    setrlimit(RLIMIT_FSIZE, &old_limit);
    signal(SIGXFSZ, old_handler);
    EXPECT_EQ(status, 2) << c.extra << "\n" << out;
    EXPECT_NE(out.find("(File too large)"), std::string::npos) << out;
    EXPECT_EQ(ReadText(csv), "old\n") << c.extra;
    EXPECT_EQ(ReadText(json), "old\n") << c.extra;
    struct stat report_after {};
    ASSERT_EQ(stat((report / "report.html").c_str(), &report_after), 0);
    EXPECT_EQ(report_after.st_ino, report_before.st_ino) << "the report was replaced";
    EXPECT_TRUE(testing::EntriesStartingWith(tmp.path(), ".").empty()) << "a temporary was left";
  }
}

}  // namespace vmap
