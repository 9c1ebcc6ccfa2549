#include "vmap/localization/localization_output.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
namespace {

VisualMap TwoKeyMap() {
  VisualMap map;
  for (int f : {0, 40}) {
    KeyImage k;
    k.frame_index = k.source_index = f;
    map.key_images.push_back(k);
  }
  return map;
}

LocalizationRun SampleRun() {
  LocalizationRun run;
  run.info.map_directory = "map";
  run.info.query = "query, with a comma.mp4";
  run.info.query_format = SourceFormat::kVideo;
  run.info.frame_size = {640, 480};
  run.info.matcher = "orb";
  run.info.ranking = "votes";
  LocalizationResult tracked;
  tracked.frame_index = 0;
  tracked.source_index = 3;
  tracked.timestamp = 0.1;
  tracked.source_name = "frame_000003";
  tracked.status = LocalizationStatus::kRelocalized;
  tracked.key = 0;
  tracked.next_key = 1;
  const double no_bearing = std::numeric_limits<double>::quiet_NaN();
  const HeadingEstimate to_key_heading{HeadingMethod::kDisplacementMode, 1.5, no_bearing, 30, 200, 0.15};
  const HeadingEstimate to_next_heading{HeadingMethod::kDisplacementMode, -2.0, -0.25, 40, 100, 0.4};
  tracked.to_key = {0,  true,           true,       0.75,  200,  150, cv::Matx33d::zeros(), to_key_heading,
                    {}, RelativePose{}, no_bearing, false, -42.5};
  tracked.to_next = {1,  true,           true, 0.5,  100,  50, cv::Matx33d(1, 2, 3, 4, 5, 6, 7, 8, 9), to_next_heading,
                     {}, RelativePose{}, 2.5,  true, -3.25};
  tracked.translation_known = true;
  tracked.heading_px = -2.0;
  tracked.heading_deg = -0.25;
  tracked.heading_key_px = 1.5;
  tracked.to_next.pose.valid = true;
  tracked.to_next.pose.R = cv::Matx33d(0, -1, 0, 1, 0, 0, 0, 0, 1);
  tracked.to_next.pose.t = cv::Vec3d(0.6, 0, 0.8);
  tracked.progress = 0.25;
  tracked.candidates = {{0, 120.0, true, 0.75, 150, -42.5}, {1, 80.0, true, 0.5, 50, -3.25}};
  tracked.confidence = 0.875;
  tracked.key_rank = 2;
  tracked.motion_steps = 3;
  LocalizationResult lost;
  lost.frame_index = 1;
  lost.source_index = 4;
  lost.status = LocalizationStatus::kLost;
  LocalizationResult uncertain = tracked;
  uncertain.frame_index = 2;
  uncertain.source_index = 5;
  uncertain.status = LocalizationStatus::kUncertain;
  uncertain.withheld_by = Withholding::kJumpBack;
  uncertain.confidence = 0.125;
  uncertain.key_rank = 1;
  run.frames = {tracked, lost, uncertain};
  run.summary.frames = 3;
  run.summary.uncertain = 1;
  run.summary.relocalized = 1;
  run.summary.lost = 1;
  run.summary.seconds = 0.5;
  run.summary.frames_per_second = 4.0;
  return run;
}

TEST(LocalizationOutput, CsvHasTheNamedColumnsAndOneRowPerFrame) {
  const VisualMap map = TwoKeyMap();
  const LocalizationRun run = SampleRun();
  std::string csv = LocalizationCsvHeader();
  for (const LocalizationResult& r : run.frames) csv += LocalizationCsvRow(map, r);
  std::istringstream lines(csv);
  std::string header, row0, row1, row2, extra;
  std::getline(lines, header);
  std::getline(lines, row0);
  std::getline(lines, row1);
  std::getline(lines, row2);
  EXPECT_FALSE(std::getline(lines, extra));
  for (const char* column : {"frame",
                             "source_index",
                             "status",
                             "key",
                             "next_key",
                             "similarity",
                             "verified",
                             "next_similarity",
                             "next_verified",
                             "heading_px",
                             "progress",
                             "F00",
                             "F22",
                             "heading_deg",
                             "R00",
                             "R22",
                             "tx",
                             "tz",
                             "heading_confidence",
                             "heading_key_px",
                             "heading_key_deg",
                             "heading_key_confidence",
                             "translation_sigma_deg",
                             "translation_known",
                             "guidance",
                             "log10_nfa",
                             "next_log10_nfa"}) {
    EXPECT_NE(("," + header + ",").find(std::string(",") + column + ","), std::string::npos) << column;
  }
  auto count = [](const std::string& s) { return std::count(s.begin(), s.end(), ','); };
  EXPECT_EQ(count(row0), count(header));
  EXPECT_EQ(count(row1), count(header));
  EXPECT_EQ(row0.rfind("0,3,0.100000,frame_000003,relocalized,0,1,0,40,0.75,150,200,0.5,50,100,-2,0.25,", 0), 0u)
      << row0;
  EXPECT_NE(row0.find(",1,2,3,4,5,6,7,8,9,-0.25,0,-1,0,1,0,0,0,0,1,0.6,0,0.8,0.4,1.5,,0.15,2.5,1,heading and "
                      "translation,-42.5,-3.25"),
            std::string::npos)
      << row0;
  // Unknown values are empty, not "nan".
  EXPECT_EQ(row1.find("nan"), std::string::npos) << row1;
  EXPECT_EQ(row1.rfind("1,4,,frame,lost,-1,-1,-1,-1,,0,0,,0,0,,,", 0), std::string::npos) << row1;
  EXPECT_NE(row1.find(",lost,-1,-1,-1,-1,,0,0,,0,0,,,"), std::string::npos) << row1;
  // The columns added later come last, in the order they were added: readers of older runs keep their indices.
  const std::string old_columns = "log10_nfa,next_log10_nfa";
  EXPECT_EQ(header.substr(header.size() - (old_columns + ",confidence,key_rank").size()),
            old_columns + ",confidence,key_rank");
  auto ends_with = [](const std::string& text, const std::string& end) {
    return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
  };
  EXPECT_TRUE(ends_with(row0, ",-42.5,-3.25,0.875,2")) << row0;
  EXPECT_TRUE(ends_with(row1, ",,-1")) << row1;
  EXPECT_NE(row2.find(",uncertain,"), std::string::npos) << row2;
  EXPECT_NE(row2.find(",none: position uncertain (jump back),"), std::string::npos) << row2;
  const std::string with_experiences = LocalizationCsvHeader(true);
  EXPECT_NE(with_experiences.find(",experience,next_experience,confidence,key_rank\n"), std::string::npos);
}

TEST(LocalizationOutput, JsonReadsBackWithItsSummary) {
  const VisualMap map = TwoKeyMap();
  const LocalizationRun run = SampleRun();
  ::vmap::testing::ScopedTempDir tmp;
  const auto file = tmp.path() / "run.json";
  WriteFileAtomically(file, LocalizationRunJson(map, run));
  const auto doc = nlohmann::json::parse(std::ifstream(file));
  EXPECT_EQ(doc["format"], "vmap-localization");
  EXPECT_DOUBLE_EQ(doc["summary"]["share_lost"].get<double>(), 1.0 / 3.0);
  EXPECT_TRUE(doc["frames"][1]["heading_px"].is_null());
  EXPECT_TRUE(doc["frames"][1]["pose"].is_null());
  EXPECT_EQ(doc["frames"][0]["pose"]["t"], nlohmann::json::array({0.6, 0.0, 0.8}));
  EXPECT_EQ(doc["frames"][0]["pose"]["R"][1], -1.0);
  EXPECT_DOUBLE_EQ(doc["frames"][0]["heading_deg"].get<double>(), -0.25);
  EXPECT_DOUBLE_EQ(doc["frames"][0]["heading_key_px"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(doc["frames"][0]["heading_confidence"].get<double>(), 0.4);
  EXPECT_DOUBLE_EQ(doc["frames"][0]["heading_key_confidence"].get<double>(), 0.15);
  EXPECT_TRUE(doc["frames"][1]["heading_key_px"].is_null());
  EXPECT_TRUE(doc["frames"][1]["heading_confidence"].is_null());
  EXPECT_DOUBLE_EQ(doc["frames"][0]["translation_sigma_deg"].get<double>(), 2.5);
  EXPECT_EQ(doc["frames"][0]["guidance"], "heading and translation");
  EXPECT_EQ(doc["frames"][1]["guidance"], "none: lost");
  EXPECT_EQ(doc["frames"][2]["guidance"], "none: position uncertain (jump back)");
  EXPECT_EQ(doc["frames"][2]["withheld_by"], "jump back");
  EXPECT_TRUE(doc["frames"][0]["withheld_by"].is_null()) << "a tracked frame is withheld by nothing";
  EXPECT_EQ(doc["frames"][2]["status"], "uncertain");
  EXPECT_DOUBLE_EQ(doc["frames"][0]["confidence"].get<double>(), 0.875);
  EXPECT_EQ(doc["frames"][0]["key_rank"], 2);
  EXPECT_TRUE(doc["frames"][1]["confidence"].is_null());
  EXPECT_EQ(doc["frames"][1]["key_rank"], -1);
  EXPECT_EQ(doc["frames"][0]["motion_steps"], 3);
  EXPECT_EQ(doc["summary"]["uncertain"], 1);
  EXPECT_EQ(doc["frames"][0]["key_frame"], 0);
  EXPECT_EQ(doc["frames"][0]["next_key_frame"], 40);
  const LocalizationRun back = ReadLocalizationRun(file);
  EXPECT_EQ(back.info.query, run.info.query);
  EXPECT_EQ(back.info.query_format, SourceFormat::kVideo);
  EXPECT_EQ(back.info.frame_size, cv::Size(640, 480));
  EXPECT_EQ(back.summary.frames, 3);
  EXPECT_EQ(back.summary.lost, 1);
  EXPECT_EQ(back.summary.uncertain, 1);
  ASSERT_EQ(back.frames.size(), 3u);
  const LocalizationResult& r = back.frames[0];
  EXPECT_EQ(r.status, LocalizationStatus::kRelocalized);
  EXPECT_EQ(r.source_index, 3);
  EXPECT_EQ(r.key, 0);
  EXPECT_EQ(r.next_key, 1);
  EXPECT_DOUBLE_EQ(r.to_key.similarity, 0.75);
  EXPECT_EQ(r.to_next.num_verified, 50);
  EXPECT_EQ(r.to_next.F, cv::Matx33d(1, 2, 3, 4, 5, 6, 7, 8, 9));
  EXPECT_DOUBLE_EQ(r.progress, 0.25);
  EXPECT_DOUBLE_EQ(r.heading_key_px, 1.5);
  ASSERT_EQ(r.candidates.size(), 2u);
  EXPECT_EQ(r.candidates[1].num_verified, 50);
  EXPECT_DOUBLE_EQ(r.candidates[1].log10_nfa, -3.25);
  EXPECT_DOUBLE_EQ(r.to_key.log10_nfa, -42.5);
  EXPECT_DOUBLE_EQ(r.to_next.log10_nfa, -3.25);
  EXPECT_TRUE(doc["frames"][1]["log10_nfa"].is_null()) << "a lost frame compared with nothing";
  EXPECT_EQ(back.frames[1].status, LocalizationStatus::kLost);
  EXPECT_TRUE(std::isnan(back.frames[1].heading_px));
  EXPECT_DOUBLE_EQ(r.confidence, 0.875);
  EXPECT_EQ(r.key_rank, 2);
  EXPECT_TRUE(std::isnan(back.frames[1].confidence));
  EXPECT_EQ(back.frames[1].key_rank, -1);
  EXPECT_EQ(r.motion_steps, 3);
  EXPECT_EQ(back.frames[1].motion_steps, 0);
  EXPECT_EQ(back.frames[2].status, LocalizationStatus::kUncertain);
  EXPECT_EQ(back.frames[2].withheld_by, Withholding::kJumpBack);
  EXPECT_EQ(back.frames[0].withheld_by, Withholding::kNone);
  EXPECT_DOUBLE_EQ(back.frames[2].confidence, 0.125);
}

// Issue 38: `vmap report RUN.json` of a run whose frames name key image 999 or -7 on a map of two.
TEST(LocalizationOutput, ARunNamingKeyImagesItsMapLacksIsRefused) {
  const VisualMap map = TwoKeyMap();
  LocalizationRun run = SampleRun();
  EXPECT_NO_THROW(CheckRunFitsMap(run, map, "run.json"));
  for (int key : {999, -7, 2}) {
    LocalizationRun bad = run;
    bad.frames[0].key = key;
    try {
      CheckRunFitsMap(bad, map, "run.json");
      ADD_FAILURE() << "key " << key << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("names key image " + std::to_string(key)), std::string::npos) << e.what();
    }
  }
  LocalizationRun bad_candidate = run;
  bad_candidate.frames[0].candidates[1].key = 40;
  EXPECT_THROW(CheckRunFitsMap(bad_candidate, map, "run.json"), InputError);
}

// A run read back against its map built again since: the key indices fit the new map, and name other images.
TEST(LocalizationOutput, ARunOfAMapBuiltAgainSinceIsRefused) {
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path file = tmp.path() / "run.json";
  WriteFileAtomically(file, LocalizationRunJson(TwoKeyMap(), SampleRun()));
  const LocalizationRun back = ReadLocalizationRun(file);
  EXPECT_NO_THROW(CheckRunFitsMap(back, TwoKeyMap(), file));
  EXPECT_NO_THROW(CheckRunFitsMap(SampleRun(), TwoKeyMap(), file)) << "a run made here records no map";

  VisualMap more = TwoKeyMap();
  more.key_images.push_back(more.key_images.back());
  more.key_images.back().frame_index = 80;
  try {
    CheckRunFitsMap(back, more, file);
    ADD_FAILURE() << "a run of 2 key images was accepted against a map of 3";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    EXPECT_NE(what.find("'map'"), std::string::npos) << what;
    EXPECT_NE(what.find("had 2 key images, and it has 3 now"), std::string::npos) << what;
    EXPECT_NE(what.find("localize again"), std::string::npos) << what;
  }

  VisualMap moved = TwoKeyMap();
  moved.key_images[1].frame_index = 28;
  try {
    CheckRunFitsMap(back, moved, file);
    ADD_FAILURE() << "a run whose next key image was map frame 40 was accepted against one at frame 28";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("next key image 1, map frame 40"), std::string::npos) << what;
    EXPECT_NE(what.find("map frame 28 now"), std::string::npos) << what;
    EXPECT_NE(what.find("localize again"), std::string::npos) << what;
  }
}

TEST(LocalizationOutput, ReadingSomethingElseIsAClearError) {
  ::vmap::testing::ScopedTempDir tmp;
  EXPECT_THROW(ReadLocalizationRun(tmp.path() / "missing.json"), InputError);
  WriteFileAtomically(tmp.path() / "map.json", "{\"format\": \"vmap-map\"}");
  try {
    ReadLocalizationRun(tmp.path() / "map.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not a localization run"), std::string::npos) << e.what();
  }
  WriteFileAtomically(tmp.path() / "broken.json", "{\"format\": \"vmap-localization\", \"frames\": 3}");
  EXPECT_THROW(ReadLocalizationRun(tmp.path() / "broken.json"), InputError);
}

// A run edited by hand: each field of the wrong kind is refused with its place in the file, never read as something
// else (2^31 was key image -2147483648, true and -0.5 were key images 1 and 0) nor let through as a raw JSON error.
TEST(LocalizationOutput, AnEditedRunNamesTheFieldItGotWrong) {
  ::vmap::testing::ScopedTempDir tmp;
  const nlohmann::json good = nlohmann::json::parse(LocalizationRunJson(TwoKeyMap(), SampleRun()));
  const fs::path file = tmp.path() / "run.json";
  auto error_of = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json doc = good;
    edit(doc);
    WriteFileAtomically(file, doc.dump());
    try {
      ReadLocalizationRun(file);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error_of([](nlohmann::json&) {}), "accepted");
  for (const nlohmann::json& key :
       {nlohmann::json(2147483648u), nlohmann::json(-0.5), nlohmann::json(true), nlohmann::json("1")}) {
    EXPECT_NE(error_of([&](nlohmann::json& d) {
                d["frames"][1]["key"] = key;
              }).find("run.json': frames[1].key must be a whole number"),
              std::string::npos)
        << key;
  }
  EXPECT_NE(error_of([](nlohmann::json& d) { d["format"] = nullptr; }).find("is not a localization run"),
            std::string::npos);
  EXPECT_NE(
      error_of([](nlohmann::json& d) { d["schema_version"] = "2"; }).find("schema_version must be a whole number"),
      std::string::npos);
  EXPECT_NE(error_of([](nlohmann::json& d) { d["query"]["path"] = 7; }).find("query.path must be a string"),
            std::string::npos);
  // The query's range too: 4294967299 was frame 3, 1e12 a negative frame.
  for (const nlohmann::json& first : {nlohmann::json(4294967299u), nlohmann::json(1e12)}) {
    EXPECT_NE(error_of([&](nlohmann::json& d) {
                d["query"]["first"] = first;
              }).find("run.json': query.first must be a whole number"),
              std::string::npos)
        << first;
  }
  // A run records its map and query as absolute paths too, read back beside the paths as given.
  ASSERT_EQ(error_of([](nlohmann::json&) {}), "accepted");
  const LocalizationRun back = ReadLocalizationRun(file);
  EXPECT_TRUE(fs::path(back.info.map_absolute_directory).is_absolute()) << back.info.map_absolute_directory;
  EXPECT_TRUE(fs::path(back.info.query_absolute_path).is_absolute()) << back.info.query_absolute_path;
  EXPECT_NE(error_of([](nlohmann::json& d) {
              d["frames"][0]["belief"] = {{0.5, 0.5}};
            }).find("frames[0].belief's key must be a whole number"),
            std::string::npos);
  EXPECT_NE(error_of([](nlohmann::json& d) { d["frames"][2] = 3; }).find("frames[2] must be an object"),
            std::string::npos);
}

}  // namespace
}  // namespace vmap
