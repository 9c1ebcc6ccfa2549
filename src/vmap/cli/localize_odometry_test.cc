// `vmap localize` with odometry: a recording's nav_msgs/Odometry topic, or --odometry FILE, adds the odometry's
// columns to every row.

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/recording_writer.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
using ::vmap::testing::Quote;
using ::vmap::testing::RunVmap;
namespace {

std::vector<std::vector<std::string>> ReadCsv(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream stream(line);
    for (std::string cell; std::getline(stream, cell, ',');) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    rows.push_back(cells);
  }
  return rows;
}

size_t Column(const std::vector<std::string>& header, const std::string& name) {
  return std::find(header.begin(), header.end(), name) - header.begin();
}

TEST(LocalizeOdometry, ARecordingsOdometryTopicGivesEveryRowItsDistance) {
  ::vmap::testing::ScopedTempDir temp("localize_odometry");
  // The synthetic drive as a recording: its frames on /cam/image_raw and the camera's path, 4 cm a frame along x,
  // on /odom, 0.1 s apart.
  const ::vmap::testing::SyntheticSequence& drive = ::vmap::testing::SidewaysDrive();
  std::vector<::vmap::testing::TestMessage> messages;
  for (size_t i = 0; i < drive.frames.size(); ++i) {
    const double t = 50.0 + 0.1 * i;
    cv::Mat gray;
    cv::cvtColor(drive.frames[i], gray, cv::COLOR_BGR2GRAY);
    const int64_t ns = static_cast<int64_t>(t * 1e9);
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", ns,
                        ::vmap::testing::SerializeImage(MessageEncoding::kCdr, t, "cam", gray, "mono8")});
    messages.push_back({"/odom", "nav_msgs/Odometry", ns,
                        ::vmap::testing::SerializeOdometry(MessageEncoding::kCdr, t, 0.04 * i, 0, 0)});
  }
  const fs::path recording = temp.path() / "drive.mcap", map = temp.path() / "map", csv = temp.path() / "run.csv";
  ::vmap::testing::WriteMcap(recording.string(), messages, "none");
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(recording) + " -o " + Quote(map) + " -q", &out), 0) << out;
  ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(recording) + " --csv " + Quote(csv) + " -q", &out), 0)
      << out;
  const auto rows = ReadCsv(csv);
  ASSERT_EQ(rows.size(), drive.frames.size() + 1);
  const std::vector<std::string>& header = rows[0];
  ASSERT_EQ(header.back(), "key_distance");
  const size_t distance = Column(header, "odometry_distance"), x = Column(header, "odometry_x");
  const size_t key = Column(header, "key"), key_distance = Column(header, "key_distance");
  ASSERT_LT(distance, header.size());
  for (size_t r = 1; r < rows.size(); ++r) {
    ASSERT_EQ(rows[r].size(), header.size()) << r;
    EXPECT_NEAR(std::stod(rows[r][distance]), 0.04 * (r - 1), 1e-6) << r;
    EXPECT_NEAR(std::stod(rows[r][x]), 0.04 * (r - 1), 1e-6) << r;
  }
  // key_distance starts again at 0 where the key image changes.
  int restarts = 0;
  for (size_t r = 2; r < rows.size(); ++r) {
    if (rows[r][key] != rows[r - 1][key] && !rows[r][key_distance].empty()) {
      EXPECT_NEAR(std::stod(rows[r][key_distance]), 0.0, 1e-9) << r;
      ++restarts;
    }
  }
  EXPECT_GE(restarts, 1);

  // --odometry FILE instead: a CSV of the same path, shifted 1 m along y.
  const fs::path odometry = temp.path() / "odom.csv";
  std::ofstream(odometry) << "timestamp,x,y,yaw\n50.0,0,1,0\n60.0,0.4,1,0\n";
  ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(recording) + " --csv " + Quote(csv) + " --odometry " +
                        Quote(odometry) + " -q",
                    &out),
            0)
      << out;
  const auto from_file = ReadCsv(csv);
  EXPECT_NEAR(std::stod(from_file[11][Column(header, "odometry_y")]), 1.0, 1e-9);
  EXPECT_NEAR(std::stod(from_file[11][x]), 0.04, 1e-9);

  // An odometry file that is not one: one error line, status 2, nothing written.
  fs::remove(csv);
  std::ofstream(odometry) << "timestamp,x,y,yaw\n50.0,0,one,0\n";
  EXPECT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(recording) + " --csv " + Quote(csv) + " --odometry " +
                        Quote(odometry) + " -q",
                    &out),
            2);
  EXPECT_EQ(out.rfind("vmap: error: ", 0), 0u) << out;
  EXPECT_NE(out.find("line 2"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(csv));
}

}  // namespace
}  // namespace vmap
