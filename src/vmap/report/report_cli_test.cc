// `vmap report` and `vmap draw` as a user runs them.

#include <sys/resource.h>
#include <sys/wait.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/localization/localization_output.h"
#include "vmap/report/html_report.h"
#include "vmap/testing/report_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using report_test::ReadText;
using testing::ScopedTempDir;

// Writes `file`, a run of one tracking frame at key image 0 (1 where the map has it) of `map` read from `directory`,
// whose query `query` need not exist.
void WriteRun(const fs::path& file, const VisualMap& map, const fs::path& directory, const std::string& query,
              const std::string& source_name = "") {
  LocalizationRun run;
  run.info.map_directory = directory.string();
  run.info.query = query;
  run.info.matcher = "orb";
  LocalizationResult frame;
  frame.status = LocalizationStatus::kTracking;
  frame.key = map.key_images.size() > 2 ? 1 : 0;
  frame.next_key = frame.key + 1;
  frame.source_name = source_name;
  run.frames = {frame};
  run.summary.frames = 1;
  run.summary.tracking = 1;
  WriteFileAtomically(file, LocalizationRunJson(map, run));
}

class ReportCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(testing::VmapBinary())) GTEST_SKIP() << "the vmap binary is not built";
  }
};

TEST_F(ReportCliTest, DrawWritesOneMatchFigure) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::WriteSyntheticMap(map);
  const fs::path png = temp.path() / "link1.png";
  const testing::CliResult run = testing::RunVmap("draw '" + map.string() + "' --link 1 -o '" + png.string() + "'");
  ASSERT_EQ(run.status, 0) << run.output;
  const cv::Mat figure = cv::imread(png.string());
  ASSERT_FALSE(figure.empty());
  EXPECT_EQ(figure.cols, 2 * 320 + 4);
  EXPECT_GT(figure.rows, 240);

  const testing::CliResult scaled = testing::RunVmap("draw '" + map.string() + "' --link 0 --width 300 -o '" +
                                                     (temp.path() / "s.jpg").string() + "'");
  ASSERT_EQ(scaled.status, 0) << scaled.output;
  EXPECT_LE(cv::imread((temp.path() / "s.jpg").string()).cols, 300);
}

TEST_F(ReportCliTest, DrawRejectsAMissingLinkOrFormat) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::WriteSyntheticMap(map);
  const testing::CliResult missing =
      testing::RunVmap("draw '" + map.string() + "' --link 9 -o '" + (temp.path() / "x.png").string() + "'");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("link 9 does not exist"), std::string::npos) << missing.output;
  const testing::CliResult format =
      testing::RunVmap("draw '" + map.string() + "' --link 0 -o '" + (temp.path() / "x.gif").string() + "'");
  EXPECT_EQ(format.status, 2);
  EXPECT_NE(format.output.find(".png"), std::string::npos) << format.output;
  EXPECT_FALSE(fs::exists(temp.path() / "x.png"));
  EXPECT_FALSE(fs::exists(temp.path() / "x.gif"));
}

TEST_F(ReportCliTest, ReportWritesIntoTheMapOrExplainsWhatIsMissing) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::WriteSyntheticMap(map);
  const testing::CliResult ok = testing::RunVmap("report '" + map.string() + "'");
  ASSERT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(fs::exists(map / kReportFileName));
  EXPECT_NE(ok.output.find("report.html"), std::string::npos);
  EXPECT_TRUE(fs::exists(map / "report/route.mp4"));
  const testing::CliResult no_video = testing::RunVmap("report --no-video '" + map.string() + "'");
  ASSERT_EQ(no_video.status, 0) << no_video.output;
  EXPECT_FALSE(fs::exists(map / "report/route.mp4"));
  EXPECT_EQ(ReadText(map / kReportFileName).find("<video"), std::string::npos);

  fs::remove(map / "correspondences.bin");
  const testing::CliResult broken = testing::RunVmap("report '" + map.string() + "'");
  EXPECT_EQ(broken.status, 2);
  EXPECT_NE(broken.output.find("correspondences.bin"), std::string::npos) << broken.output;

  const testing::CliResult none = testing::RunVmap("report '" + (temp.path() / "nothing").string() + "'");
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.output.find("nothing"), std::string::npos) << none.output;
  EXPECT_FALSE(fs::exists(temp.path() / "nothing"));
}

// A run reported against its map built again since (more key images, key 1 now another frame): its frames were
// paired with the rebuilt map's key images and its run.json rewritten to say so.
TEST_F(ReportCliTest, ARunOfAMapBuiltAgainSinceIsRefused) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::SyntheticMapOptions options;
  options.num_frames = 19;  // key images at frames 0, 9 and 18
  const VisualMap teach = report_test::WriteSyntheticMap(map, options);
  ASSERT_EQ(teach.key_images.size(), 3u);
  const fs::path file = temp.path() / "run.json";
  WriteRun(file, teach, map, (temp.path() / "gone.mp4").string());
  const testing::CliResult before = testing::RunVmap("report '" + file.string() + "'");
  ASSERT_EQ(before.status, 0) << before.output;
  fs::remove_all(temp.path() / "run_report");

  options.frames_per_key = 2;
  const VisualMap rebuilt = report_test::WriteSyntheticMap(map, options);
  ASSERT_EQ(rebuilt.key_images.size(), 10u);
  const testing::CliResult after = testing::RunVmap("report '" + file.string() + "'");
  EXPECT_EQ(after.status, 2) << after.output;
  EXPECT_NE(after.output.find("had 3 key images, and it has 10 now"), std::string::npos) << after.output;
  EXPECT_NE(after.output.find("localize again"), std::string::npos) << after.output;
  EXPECT_FALSE(fs::exists(temp.path() / "run_report")) << "a report pairing frames with other key images";
}

// The run a report keeps of itself (REPORT/run.json): its report by default went inside REPORT, which could then never
// be replaced. It is refused, saying to write it elsewhere; written elsewhere, it is the run's report.
TEST_F(ReportCliTest, TheRunKeptInAReportIsNotReportedInsideIt) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  const VisualMap teach = report_test::WriteSyntheticMap(map, {});
  WriteRun(temp.path() / "run.json", teach, map, (temp.path() / "gone.mp4").string());
  ASSERT_EQ(testing::RunVmap("report '" + (temp.path() / "run.json").string() + "'").status, 0);
  const fs::path kept = temp.path() / "run_report" / "run.json";
  ASSERT_TRUE(fs::is_regular_file(kept));
  const testing::CliResult nested = testing::RunVmap("report '" + kept.string() + "'");
  EXPECT_EQ(nested.status, 2) << nested.output;
  EXPECT_NE(nested.output.find("is the run kept in the report"), std::string::npos) << nested.output;
  EXPECT_FALSE(fs::exists(temp.path() / "run_report" / "run_report"));
  const testing::CliResult elsewhere =
      testing::RunVmap("report '" + kept.string() + "' -o '" + (temp.path() / "again").string() + "'");
  EXPECT_EQ(elsewhere.status, 0) << elsewhere.output;
  EXPECT_TRUE(fs::is_regular_file(temp.path() / "again" / kReportFileName));
}

// A run whose query and frame names are Latin-1 bytes: written raw into the UTF-8 page, they showed as replacement
// characters. Shown percent-encoded, as the map's page shows them.
TEST_F(ReportCliTest, ARunWithNamesThatAreNotUtf8HasAUtf8Page) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  const VisualMap built = report_test::WriteSyntheticMap(map);
  const fs::path file = temp.path() / "run.json";
  WriteRun(file, built, map, (temp.path() / "caf\xE9 query.mp4").string(), "frame_\xE9t\xE9");
  const testing::CliResult made = testing::RunVmap("report '" + file.string() + "'");
  ASSERT_EQ(made.status, 0) << made.output;
  const std::string page = ReadText(temp.path() / "run_report" / kReportFileName);
  EXPECT_TRUE(IsValidUtf8(page));
  EXPECT_NE(page.find("<title>vmap localization: " + (temp.path() / "caf%E9 query.mp4").string()), std::string::npos);
  EXPECT_GE(report_test::CountOccurrences(page, "caf%E9 query.mp4"), 3) << "title, heading and the Query row";
}

// `vmap report no_such_map` said "its folder 'no_such_map' does not exist; create it first", and so did a run file
// that does not exist: the page's folder was checked before the map was read.
TEST_F(ReportCliTest, AMapOrRunThatDoesNotExistIsNamedAsSuch) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "no_such_map";
  const testing::CliResult no_map = testing::RunVmap("report '" + map.string() + "'");
  EXPECT_EQ(no_map.status, 2);
  EXPECT_NE(no_map.output.find("map directory '" + map.string() + "' does not exist; build one with `vmap build`"),
            std::string::npos)
      << no_map.output;
  EXPECT_EQ(no_map.output.find("create it"), std::string::npos) << no_map.output;
  const fs::path run = temp.path() / "nonexist.json";
  const testing::CliResult no_run = testing::RunVmap("report '" + run.string() + "'");
  EXPECT_EQ(no_run.status, 2);
  EXPECT_NE(no_run.output.find("the localization run '" + run.string() + "' does not exist"), std::string::npos)
      << no_run.output;
  EXPECT_EQ(no_run.output.find("create it"), std::string::npos) << no_run.output;
  EXPECT_TRUE(fs::is_empty(temp.path())) << "nothing written";
}

// Options of one kind of report given for the other were ignored: `vmap report MAP -o elsewhere` wrote into the
// map, and a run's report took --figure-width, --thumbnail-width and --no-video and exited 0.
TEST_F(ReportCliTest, OptionsOfTheOtherKindOfReportAreRefused) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  const VisualMap built = report_test::WriteSyntheticMap(map);
  const fs::path elsewhere = temp.path() / "elsewhere";
  const testing::CliResult map_output =
      testing::RunVmap("report '" + map.string() + "' -o '" + elsewhere.string() + "'");
  EXPECT_EQ(map_output.status, 2);
  EXPECT_NE(map_output.output.find("-o"), std::string::npos) << map_output.output;
  EXPECT_NE(map_output.output.find("a map's report is written into the map"), std::string::npos) << map_output.output;
  EXPECT_FALSE(fs::exists(elsewhere));
  EXPECT_FALSE(fs::exists(map / kReportFileName));

  const fs::path file = temp.path() / "run.json";
  WriteRun(file, built, map, (temp.path() / "gone.mp4").string());
  for (const std::string flag : {"--figure-width 500", "--thumbnail-width 100", "--no-video"}) {
    const testing::CliResult run = testing::RunVmap("report '" + file.string() + "' " + flag);
    EXPECT_EQ(run.status, 2) << flag << "\n" << run.output;
    EXPECT_NE(run.output.find(flag.substr(0, flag.find(' ')) + " is for a map's report"), std::string::npos)
        << run.output;
    EXPECT_FALSE(fs::exists(temp.path() / "run_report")) << flag;
  }
}

// The largest file under `directory`, in bytes.
std::uintmax_t LargestFile(const fs::path& directory) {
  std::uintmax_t largest = 0;
  for (const auto& entry : fs::recursive_directory_iterator(directory)) {
    if (entry.is_regular_file()) largest = std::max(largest, entry.file_size());
  }
  return largest;
}

// `vmap report MAP extra` under a file size limit of `limit` bytes: a write that fails part way, as on a full disk.
testing::CliResult ReportUnderSizeLimit(const fs::path& map, const std::string& extra, rlim_t limit) {
  struct rlimit old_limit {};
  EXPECT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_DFL);  // as a shell leaves it: vmap ignores it itself
  struct rlimit small = old_limit;
  small.rlim_cur = limit;
  EXPECT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  const testing::CliResult result = testing::RunVmap("report '" + map.string() + "' " + extra);
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  return result;
}

// A report whose writing failed part way was put in place half: a route video cut short was accepted (cv::VideoWriter
// ignores failed writes), and report/ was replaced before report.html failed to be written.
TEST_F(ReportCliTest, AReportWhoseWritingFailsPartWayLeavesTheOldOne) {
  ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::SyntheticMapOptions options;
  options.frames_per_key = 2;  // many key images: a route video larger than every picture and the page
  options.frame_size = {640, 480};
  report_test::WriteSyntheticMap(map, options);
  const testing::CliResult made =
      testing::RunVmap("report '" + map.string() + "' --figure-width 200 --thumbnail-width 640");
  ASSERT_EQ(made.status, 0) << made.output;
  const std::string page = ReadText(map / kReportFileName);
  const std::string video = ReadText(map / "report/route.mp4");
  const std::string thumbnail = ReadText(map / "report/keys/000000.jpg");
  const std::uintmax_t pictures = std::max(LargestFile(map / "report/keys"), LargestFile(map / "report/links"));
  ASSERT_GT(video.size(), std::max<std::uintmax_t>(pictures, page.size()) + 1024);

  // The video cut short, everything else written whole.
  const testing::CliResult cut_video = ReportUnderSizeLimit(map, "--figure-width 200 --thumbnail-width 640",
                                                            std::max<std::uintmax_t>(pictures, page.size()) + 512);
  EXPECT_EQ(cut_video.status, 2) << cut_video.output;
  EXPECT_NE(cut_video.output.find("cannot write the route video '" + (map / "report/route.mp4").string() + "'"),
            std::string::npos)
      << cut_video.output;
  EXPECT_TRUE(ReadText(map / "report/route.mp4") == video) << "the old video was replaced";
  EXPECT_TRUE(ReadText(map / kReportFileName) == page) << "the old page was replaced";

  // The pictures written whole (smaller thumbnails, no video), the page cut short: sizes taken from the report of
  // a copy.
  const std::string smaller = "--figure-width 200 --thumbnail-width 100 --no-video";
  const fs::path copy = temp.path() / "copy";
  fs::copy(map, copy, fs::copy_options::recursive);
  ASSERT_EQ(testing::RunVmap("report '" + copy.string() + "' " + smaller).status, 0);
  const std::uintmax_t small_pictures = LargestFile(copy / "report");
  ASSERT_GT(ReadText(copy / kReportFileName).size(), small_pictures + 1024);
  const testing::CliResult cut_page = ReportUnderSizeLimit(map, smaller, small_pictures + 512);
  EXPECT_EQ(cut_page.status, 2) << cut_page.output;
  EXPECT_NE(cut_page.output.find(kReportFileName), std::string::npos) << cut_page.output;
  EXPECT_TRUE(ReadText(map / kReportFileName) == page) << "the old page was replaced";
  EXPECT_TRUE(ReadText(map / "report/keys/000000.jpg") == thumbnail) << "the old page's pictures were replaced";
  EXPECT_TRUE(fs::exists(map / "report/route.mp4")) << "the old page's video was removed";
  for (const auto& entry : fs::directory_iterator(map)) {
    EXPECT_NE(entry.path().filename().string()[0], '.') << "a temporary was left: " << entry.path();
  }
}

}  // namespace
}  // namespace vmap
