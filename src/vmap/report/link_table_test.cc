#include "vmap/report/link_table.h"

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/evaluation/evaluation_json.h"
#include "vmap/report/html_report.h"
#include "vmap/testing/report_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

// An evaluation of `map`'s links as `vmap eval` would write it: every other link usable.
MapEvaluation EvaluationOf(const VisualMap& map) {
  MapEvaluation e;
  e.ground_truth_path = "poses.txt";
  e.ground_truth_format = GroundTruthFormat::kKitti;
  e.camera = Camera::Make(300, 300, 159.5, 119.5, {}, {320, 240});
  for (size_t i = 0; i < map.links.size(); ++i) {
    LinkEvaluation l;
    l.link = static_cast<int>(i);
    l.from_frame = map.key_images[map.links[i].from_key].frame_index;
    l.to_frame = map.key_images[map.links[i].to_key].frame_index;
    l.has_ground_truth = true;
    l.pose_source = "stored";
    l.rotation_error_deg = i % 2 == 0 ? 0.25 : 7.5;
    l.translation_error_deg = 3.0;
    l.true_parallax_px = 20.0;
    l.verified_within = 0.97;
    l.rejected_within = 0.4;
    l.usable = i % 2 == 0;
    e.links.push_back(l);
    ++e.summary.links;
    ++e.summary.evaluated_links;
    e.summary.usable_links += l.usable ? 1 : 0;
  }
  e.summary.usable_share = static_cast<double>(e.summary.usable_links) / e.summary.links;
  e.summary.rotation_error_deg_median = 0.25;
  e.summary.translation_error_deg_median = 3.0;
  return e;
}

TEST(LinkTableTest, TheReportShowsTheEvaluationOfItsOwnLinksOnly) {
  testing::ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  const VisualMap map = report_test::WriteSyntheticMap(dir);
  MapReportOptions options;
  options.route_video = false;

  // No evaluation: the table of links is there, without ground-truth columns.
  WriteMapReport(dir, options);
  std::string html = report_test::ReadText(dir / kReportFileName);
  EXPECT_EQ(report_test::CountOccurrences(html, "<tr data-link="), static_cast<int>(map.links.size()));
  EXPECT_EQ(html.find("usable share"), std::string::npos);
  EXPECT_NE(html.find("has no camera"), std::string::npos);

  // An evaluation of this map: summary cards, a row per link with its errors, and the figures' captions.
  const MapEvaluation evaluation = EvaluationOf(map);
  std::ofstream(dir / kEvaluationFileName) << EvaluationToJson(evaluation);
  WriteMapReport(dir, options);
  html = report_test::ReadText(dir / kReportFileName);
  EXPECT_NE(html.find("usable share"), std::string::npos);
  EXPECT_NE(html.find(std::to_string(evaluation.summary.usable_links) + " / " + std::to_string(map.links.size())),
            std::string::npos);
  EXPECT_NE(html.find("7.50&deg;"), std::string::npos);
  // Unusable links are shaded.
  EXPECT_EQ(report_test::CountOccurrences(html, "<tr class=\"below-tau\" data-link="),
            evaluation.summary.links - evaluation.summary.usable_links);
  EXPECT_EQ(report_test::CountOccurrences(html, "NOT usable"),
            evaluation.summary.links - evaluation.summary.usable_links);

  // An evaluation of other links (the map was rebuilt since) is ignored.
  MapEvaluation stale = evaluation;
  stale.links[1].to_frame += 1;
  std::ofstream(dir / kEvaluationFileName) << EvaluationToJson(stale);
  EXPECT_FALSE(ReadMatchingEvaluation(dir, map));
  WriteMapReport(dir, options);
  EXPECT_EQ(report_test::ReadText(dir / kReportFileName).find("usable share"), std::string::npos);
  std::ofstream(dir / kEvaluationFileName) << "not json";
  EXPECT_FALSE(ReadMatchingEvaluation(dir, map));
  // One of a later layout is not read as this one.
  nlohmann::json later = nlohmann::json::parse(EvaluationToJson(evaluation));
  ASSERT_EQ(later["schema_version"], 1);
  later["schema_version"] = 2;
  std::ofstream(dir / kEvaluationFileName) << later.dump();
  EXPECT_FALSE(ReadMatchingEvaluation(dir, map));
  later["schema_version"] = 1;
  std::ofstream(dir / kEvaluationFileName) << later.dump();
  EXPECT_TRUE(ReadMatchingEvaluation(dir, map));
}

}  // namespace
}  // namespace vmap
