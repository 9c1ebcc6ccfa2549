// `vmap report` and `vmap draw` as a user runs them.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/report/html_report.h"
#include "vmap/testing/report_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using report_test::ReadText;
using testing::ScopedTempDir;

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

}  // namespace
}  // namespace vmap
