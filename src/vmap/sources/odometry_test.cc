#include "vmap/sources/odometry.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/recording_writer.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

std::string ErrorOfCsv(const std::string& text) {
  testing::ScopedTempDir temp("odometry_csv");
  std::ofstream(temp.path() / "odom.csv") << text;
  try {
    ReadOdometryCsv(temp.path() / "odom.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(OdometryCsv, ReadsTimestampedPoses) {
  testing::ScopedTempDir temp("odometry_csv_ok");
  std::ofstream(temp.path() / "odom.csv")
      << "timestamp,x,y,yaw\n# start\n0.0,0,0,0\n0.5, 0.2,0.0,0.1,extra\n1.0,0.4,0.1,7\n";
  const std::vector<OdometrySample> samples = ReadOdometryCsv(temp.path() / "odom.csv");
  ASSERT_EQ(samples.size(), 3u);
  EXPECT_DOUBLE_EQ(samples[1].x, 0.2);
  EXPECT_NEAR(samples[2].yaw, 7.0 - 2 * M_PI, 1e-12);  // wrapped
  const OdometryTrack track(samples);
  EXPECT_NEAR(track.DistanceAt(0.25), 0.1, 1e-12);
  EXPECT_NEAR(track.DistanceAt(0.75), 0.2 + 0.5 * std::hypot(0.2, 0.1), 1e-12);
  EXPECT_NEAR(track.DistanceAt(1.0), 0.2 + std::hypot(0.2, 0.1), 1e-12);
  EXPECT_TRUE(std::isnan(track.DistanceAt(2.0)));
}

TEST(OdometryCsv, WrittenSamplesReadBackExactly) {
  testing::ScopedTempDir temp("odometry_csv_write");
  const std::vector<OdometrySample> samples = {{1000.1, 0.1, -2.0 / 3.0, 0.25}, {1000.2, 1.0 / 3.0, 1e-17, -3.0}};
  std::ofstream(temp.path() / "odom.csv") << OdometryCsv(samples);
  const std::vector<OdometrySample> read = ReadOdometryCsv(temp.path() / "odom.csv");
  ASSERT_EQ(read.size(), samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(read[i].timestamp, samples[i].timestamp);
    EXPECT_EQ(read[i].x, samples[i].x);
    EXPECT_EQ(read[i].y, samples[i].y);
    EXPECT_EQ(read[i].yaw, samples[i].yaw);
  }
}

TEST(OdometryCsv, MalformedFilesAreRefusedNamingTheLine) {
  EXPECT_NE(ErrorOfCsv("").find("no timestamp"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0,0,0\n1,0,0\n").find("line 2"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0,0,0\n1,x,0,0\n").find("line 2"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0,0,0\n1,inf,0,0\n").find("finite"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("1,0,0,0\n0.5,0,0,0\n").find("goes back"), std::string::npos);
  EXPECT_THROW(ReadOdometryCsv("/nonexistent/odom.csv"), InputError);
}

TEST(OdometryMessages, DecodesBothSerializations) {
  for (const MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    const std::vector<uint8_t> data = testing::SerializeOdometry(encoding, 12.25, 1.5, -2.0, 0.75);
    const OdometrySample sample = DecodeOdometryMessage(data.data(), data.size(), encoding, "odometry");
    EXPECT_DOUBLE_EQ(sample.timestamp, 12.25);
    EXPECT_DOUBLE_EQ(sample.x, 1.5);
    EXPECT_DOUBLE_EQ(sample.y, -2.0);
    EXPECT_NEAR(sample.yaw, 0.75, 1e-12);
    EXPECT_THROW(DecodeOdometryMessage(data.data(), 40, encoding, "odometry"), InputError);  // cut short
  }
}

TEST(OdometryMessages, AreReadFromARecordingsTopic) {
  testing::ScopedTempDir temp("odometry_recording");
  std::vector<testing::TestMessage> messages;
  for (int i = 0; i < 5; ++i) {
    const double t = 100.0 + 0.1 * i;
    messages.push_back({"/odom", "nav_msgs/Odometry", static_cast<int64_t>(t * 1e9),
                        testing::SerializeOdometry(MessageEncoding::kCdr, t, 0.05 * i, 0.0, 0.0)});
  }
  const fs::path bag = temp.path() / "run.mcap";
  testing::WriteMcap(bag.string(), messages, "zstd");
  const std::vector<OdometrySample> samples = ReadOdometry(bag.string(), "");
  ASSERT_EQ(samples.size(), 5u);
  EXPECT_DOUBLE_EQ(samples[4].x, 0.2);
  EXPECT_NEAR(samples[4].timestamp, 100.4, 1e-9);
  EXPECT_THROW(ReadOdometry(bag.string(), "/other"), InputError);
  EXPECT_THROW(ReadOdometry((temp.path() / "odom.csv").string(), "/odom"), InputError);  // a topic of a CSV
}

}  // namespace
}  // namespace vmap
