// `vmap report` and `vmap draw` as a user runs them.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/report/html_report.h"
#include "vmap/report/report_test_util.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using report_test::ReadText;
using report_test::TempDir;

struct CommandResult {
  int status;
  std::string output;
};

CommandResult Vmap(const std::string& arguments, const fs::path& work) {
  const fs::path log = work / "vmap.log";
  const std::string command = std::string("'") + VMAP_BINARY + "' " + arguments + " > '" + log.string() + "' 2>&1";
  const int raw = std::system(command.c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, ReadText(log)};
}

class ReportCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(VMAP_BINARY)) GTEST_SKIP() << "the vmap binary is not built";
  }
};

TEST_F(ReportCliTest, DrawWritesOneMatchFigure) {
  TempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::WriteSyntheticMap(map);
  const fs::path png = temp.path() / "link1.png";
  const CommandResult run = Vmap("draw '" + map.string() + "' --link 1 -o '" + png.string() + "'", temp.path());
  ASSERT_EQ(run.status, 0) << run.output;
  const cv::Mat figure = cv::imread(png.string());
  ASSERT_FALSE(figure.empty());
  EXPECT_EQ(figure.cols, 2 * 320 + 4);
  EXPECT_GT(figure.rows, 240);

  const CommandResult scaled = Vmap("draw '" + map.string() + "' --link 0 --width 300 -o '" + (temp.path() / "s.jpg").string() +
                              "'",
                          temp.path());
  ASSERT_EQ(scaled.status, 0) << scaled.output;
  EXPECT_LE(cv::imread((temp.path() / "s.jpg").string()).cols, 300);
}

TEST_F(ReportCliTest, DrawRejectsAMissingLinkOrFormat) {
  TempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::WriteSyntheticMap(map);
  const CommandResult missing = Vmap("draw '" + map.string() + "' --link 9 -o '" + (temp.path() / "x.png").string() + "'",
                           temp.path());
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("link 9 does not exist"), std::string::npos) << missing.output;
  const CommandResult format = Vmap("draw '" + map.string() + "' --link 0 -o '" + (temp.path() / "x.gif").string() + "'",
                          temp.path());
  EXPECT_EQ(format.status, 2);
  EXPECT_NE(format.output.find(".png"), std::string::npos) << format.output;
  EXPECT_FALSE(fs::exists(temp.path() / "x.png"));
  EXPECT_FALSE(fs::exists(temp.path() / "x.gif"));
}

TEST_F(ReportCliTest, ReportWritesIntoTheMapOrExplainsWhatIsMissing) {
  TempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::WriteSyntheticMap(map);
  const CommandResult ok = Vmap("report '" + map.string() + "'", temp.path());
  ASSERT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(fs::exists(map / kReportFileName));
  EXPECT_NE(ok.output.find("report.html"), std::string::npos);
  EXPECT_TRUE(fs::exists(map / "report/route.mp4"));
  const CommandResult no_video = Vmap("report --no-video '" + map.string() + "'", temp.path());
  ASSERT_EQ(no_video.status, 0) << no_video.output;
  EXPECT_FALSE(fs::exists(map / "report/route.mp4"));
  EXPECT_EQ(ReadText(map / kReportFileName).find("<video"), std::string::npos);

  fs::remove(map / "correspondences.bin");
  const CommandResult broken = Vmap("report '" + map.string() + "'", temp.path());
  EXPECT_EQ(broken.status, 2);
  EXPECT_NE(broken.output.find("correspondences.bin"), std::string::npos) << broken.output;

  const CommandResult none = Vmap("report '" + (temp.path() / "nothing").string() + "'", temp.path());
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.output.find("nothing"), std::string::npos) << none.output;
  EXPECT_FALSE(fs::exists(temp.path() / "nothing"));
}

}  // namespace
}  // namespace vmap
