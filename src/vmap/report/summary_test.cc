#include "vmap/report/summary.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace vmap {

namespace {

SweepResult TwoRows() {
  SweepResult sweep;
  sweep.input.path = "video.mp4";
  sweep.num_frames = 100;
  for (double tau : {0.3, 0.6}) {
    SweepRow row;
    row.tau = tau;
    row.num_key_images = tau < 0.5 ? 5 : 20;
    row.key_image_percent = row.num_key_images;
    row.min_verified = 30;
    row.max_verified = 90;
    row.mean_verified = 55.5;
    row.quality = tau < 0.5 ? 0.7 : 0.6;
    sweep.rows.push_back(row);
  }
  sweep.best_row = 0;
  return sweep;
}

}  // namespace

TEST(Summary, MapSummaryHasThePapersNumbers) {
  VisualMap map;
  map.input.path = "in.mp4";
  map.num_frames = 200;
  map.key_images.resize(3);
  Link a, b;
  a.num_verified = 40;
  a.similarity = 0.8;
  b.num_verified = 60;
  b.similarity = 0.9;
  map.links = {a, b};
  map.seconds = 2.0;
  const std::string text = FormatMapSummary(map, QualityMean::kArithmetic);
  EXPECT_NE(text.find("frames (n)      200"), std::string::npos) << text;
  EXPECT_NE(text.find("key images (m)  3 (1.5% of frames)"), std::string::npos) << text;
  EXPECT_NE(text.find("min 40  max 60  mean 50.0"), std::string::npos) << text;
  EXPECT_NE(text.find("100.0 frames/s"), std::string::npos) << text;
  EXPECT_EQ(text.find("camera mask"), std::string::npos) << text;

  map.camera_mask = cv::Mat(48, 64, CV_8UC1, cv::Scalar(255));
  map.camera_mask.colRange(0, 16).setTo(0);
  EXPECT_NE(
      FormatMapSummary(map, QualityMean::kArithmetic).find("camera mask     64x48, features on 75.0% of the pixels"),
      std::string::npos);
}

TEST(Summary, SweepTablesMarkTheBestTau) {
  const SweepResult sweep = TwoRows();
  const std::string md = SweepToMarkdown(sweep);
  EXPECT_NE(md.find("| **0.30** | 5 |"), std::string::npos) << md;
  EXPECT_NE(md.find("Best tau by Q: 0.30"), std::string::npos) << md;
  const std::string csv = SweepToCsv(sweep);
  EXPECT_NE(csv.find("0.3000,5,"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  const auto json = nlohmann::json::parse(SweepToJson(sweep));
  EXPECT_EQ(json["rows"].size(), 2u);
  EXPECT_DOUBLE_EQ(json["best_tau"].get<double>(), 0.3);
  EXPECT_EQ(json["rows"][1]["key_images"], 20);
}

// Thresholds two decimals would read alike keep their own: two rows of "0.10" did not say which was best.
TEST(Summary, SweepTablesTellCloseThresholdsApart) {
  SweepResult sweep = TwoRows();
  sweep.rows[0].tau = 0.101;
  sweep.rows[1].tau = 0.104;
  sweep.best_row = 1;
  const std::string md = SweepToMarkdown(sweep);
  EXPECT_NE(md.find("| 0.101 | 5 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| **0.104** | 20 |"), std::string::npos) << md;
  EXPECT_NE(md.find("Best tau by Q: 0.104"), std::string::npos) << md;
}

// sweep.csv wrote both 0.12341 and 0.12344 as 0.1234: two rows of one threshold, neither matching sweep.json's.
TEST(Summary, SweepCsvTellsCloseThresholdsApart) {
  SweepResult sweep = TwoRows();
  sweep.rows[0].tau = 0.12341;
  sweep.rows[1].tau = 0.12344;
  const std::string csv = SweepToCsv(sweep);
  EXPECT_NE(csv.find("\n0.12341,5,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n0.12344,20,"), std::string::npos) << csv;
  sweep.rows[0].tau = 0.5;
  EXPECT_NE(SweepToCsv(sweep).find("\n0.5000,5,"), std::string::npos) << "a threshold four decimals hold keeps them";
}

}  // namespace vmap
