#include "vmap/evaluation/evaluation_json.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// An evaluation whose every link field and summary field has a value of its own (none a default).
MapEvaluation Distinct() {
  MapEvaluation evaluation;
  evaluation.map_path = "map";
  evaluation.camera = Camera::Make(500, 510, 320, 240, {}, {640, 480});
  LinkEvaluation e;
  e.link = 3, e.from_frame = 40, e.to_frame = 52, e.from_source = 80, e.to_source = 104;
  e.below_tau = true, e.planar = true, e.similarity = 0.61, e.num_verified = 120, e.num_rejected = 33;
  e.has_ground_truth = true, e.pose_source = "fundamental";
  e.true_rotation_deg = 4.5, e.true_baseline = 0.3, e.true_parallax_px = 12.5, e.consistent_matches = 140;
  e.rotation_error_deg = 0.7, e.translation_error_deg = 8.5;
  e.verified_sampson_median = 0.4, e.verified_within = 0.9, e.rejected_sampson_median = 7.5, e.rejected_within = 0.1;
  e.usable = true, e.strict_usable = true, e.translation_known = true, e.translation_sigma_deg = 1.25;
  e.true_pose_cost_excess = 3.5;
  evaluation.links = {e};
  EvaluationSummary& s = evaluation.summary;
  s.links = 9, s.evaluated_links = 8, s.usable_links = 7, s.usable_share = 0.875, s.links_with_pose = 6;
  s.rotation_error_deg_median = 0.5, s.true_pose_cost_excess_median = 1.5, s.translation_error_deg_median = 6.5;
  s.verified_within_mean = 0.85, s.rejected_within_mean = 0.15, s.strict_usable_links = 5;
  s.strict_usable_share = 0.625, s.flagged_links = 4, s.flagged_wrong_links = 3, s.flagged_wrong_share = 0.75;
  s.unflagged_links = 2, s.unflagged_right_links = 1, s.unflagged_right_share = 0.5, s.unflagged_usable_links = 2;
  s.unflagged_usable_share = 1.0, s.unflagged_reversed_links = 1;
  return evaluation;
}

}  // namespace

// Writer and reader go through one list of keys: what is written reads back to the same document, key for key.
TEST(EvaluationJson, EveryKeyWrittenIsReadBack) {
  const MapEvaluation written = Distinct();
  const std::string text = EvaluationToJson(written);
  const nlohmann::json doc = nlohmann::json::parse(text);
  EXPECT_EQ(doc["links"][0].size(), 27u);
  EXPECT_EQ(doc["summary"].size(), 21u);
  testing::ScopedTempDir tmp;
  const fs::path file = tmp.path() / kEvaluationFileName;
  std::ofstream(file) << text;
  const MapEvaluation back = ReadEvaluation(file.string());
  EXPECT_EQ(EvaluationToJson(back), text);
  ASSERT_EQ(back.links.size(), 1u);
  EXPECT_EQ(back.links[0].pose_source, "fundamental");
  EXPECT_EQ(back.links[0].to_source, 104);
  EXPECT_DOUBLE_EQ(back.links[0].true_pose_cost_excess, 3.5);
  EXPECT_EQ(back.summary.unflagged_reversed_links, 1);
}

// Files of earlier versions lack keys: each reads as it did (the sources are the frames, a stored pose's
// translation known, numbers unknown); a link without its index is malformed, as is a value of the wrong kind.
TEST(EvaluationJson, MissingKeysReadAsEarlierFilesMeantThem) {
  nlohmann::json doc = nlohmann::json::parse(EvaluationToJson(Distinct()));
  doc["links"][0] = {{"link", 0}, {"from_frame", 5}, {"to_frame", 9}, {"pose_source", "stored"}};
  doc["summary"] = nlohmann::json::object();
  testing::ScopedTempDir tmp;
  const fs::path file = tmp.path() / kEvaluationFileName;
  std::ofstream(file) << doc.dump();
  const MapEvaluation back = ReadEvaluation(file.string());
  ASSERT_EQ(back.links.size(), 1u);
  const LinkEvaluation& e = back.links[0];
  EXPECT_EQ(e.from_source, 5);
  EXPECT_EQ(e.to_source, 9);
  EXPECT_TRUE(e.translation_known);
  EXPECT_EQ(e.similarity, 0.0);
  EXPECT_TRUE(std::isnan(e.true_parallax_px));
  EXPECT_EQ(back.summary.links, 0);
  EXPECT_TRUE(std::isnan(back.summary.usable_share));

  doc["links"][0] = {{"from_frame", 5}, {"to_frame", 9}};
  std::ofstream(file) << doc.dump();
  EXPECT_THROW(ReadEvaluation(file.string()), InputError);
  doc["links"][0] = {{"link", 0}, {"from_frame", 5}, {"to_frame", 9}, {"usable", "yes"}};
  std::ofstream(file) << doc.dump();
  EXPECT_THROW(ReadEvaluation(file.string()), InputError);
  doc["links"][0] = {{"link", 0}, {"from_frame", 5}, {"to_frame", 9}, {"pose_source", "none"}};
  std::ofstream(file) << doc.dump();
  EXPECT_FALSE(ReadEvaluation(file.string()).links[0].translation_known);
}

}  // namespace vmap
