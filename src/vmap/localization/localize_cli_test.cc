// End-to-end tests of `vmap localize`, `vmap route` and the report of a run, on the shared sequences; and the
// bracket test against truth (docs/measurements/localization.md) on subsets of kitti07 and redkitchen.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/evaluation/ground_truth.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localization_output.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/map/map_io.h"
#include "vmap/report/html_report.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;
using ::vmap::testing::Quote;
using ::vmap::testing::RunVmap;
namespace {

fs::path Shared() { return ::vmap::testing::SharedDir(); }

std::vector<std::string> Lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The cells of column `name` in a CSV `vmap localize` wrote, one a frame.
std::vector<std::string> CsvColumn(const fs::path& csv, const std::string& name) {
  auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
  };
  const std::vector<std::string> rows = Lines(csv);
  if (rows.empty()) return {};
  const std::vector<std::string> header = split(rows[0]);
  const size_t column = std::find(header.begin(), header.end(), name) - header.begin();
  EXPECT_LT(column, header.size()) << name << " is not a column of " << csv;
  std::vector<std::string> cells;
  for (size_t r = 1; r < rows.size(); ++r) {
    const std::vector<std::string> row = split(rows[r]);
    cells.push_back(column < row.size() ? row[column] : "");
  }
  return cells;
}

// A map of the first 240 frames of lab_floor.mp4, built once by the binary for the tests of this file.
const fs::path& LabMap() {
  static ::vmap::testing::ScopedTempDir directory;
  static const fs::path map = [] {
    const fs::path path = directory.path() / "lab_map";
    std::string out;
    EXPECT_EQ(
        RunVmap("build " + Quote(Shared() / "data/lab_floor/lab_floor.mp4") + " -o " + Quote(path) + " --last 239 -q",
                &out),
        0)
        << out;
    return path;
  }();
  return map;
}

TEST(LocalizeCli, LocalizesARepeatOfTheTeachRunAndWritesCsvAndJson) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  const fs::path csv = tmp.path() / "run.csv", json = tmp.path() / "run.json";
  ASSERT_EQ(RunVmap("localize " + Quote(LabMap()) + " " + Quote(Shared() / "data/lab_floor/lab_floor.mp4") +
                        " --first 1 --last 239 --stride 4 --csv " + Quote(csv) + " --json " + Quote(json),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("frames          60"), std::string::npos) << out;
  const std::vector<std::string> rows = Lines(csv);
  ASSERT_EQ(rows.size(), 61u);
  EXPECT_EQ(rows[0].rfind("frame,source_index,timestamp,source_name,status,key,next_key,", 0), 0u) << rows[0];
  const auto doc = nlohmann::json::parse(std::ifstream(json));
  EXPECT_EQ(doc["summary"]["frames"], 60);
  const double shares = doc["summary"]["share_tracking"].get<double>() +
                        doc["summary"]["share_relocalized"].get<double>() + doc["summary"]["share_lost"].get<double>();
  EXPECT_NEAR(shares, 1.0, 1e-9);
  EXPECT_LE(doc["summary"]["lost"].get<int>(), 3) << "the teach run itself must localize";
  // Each frame is between the key images around it in the teach run.
  const VisualMap map = ReadMap(LabMap());
  int bracketed = 0;
  for (const auto& frame : doc["frames"]) {
    const auto [before, after] = KeysAround(map, frame["source_index"].get<int>());
    const int key = frame["key"].get<int>();
    bracketed += key >= 0 && (key == before || key == after);
  }
  EXPECT_GE(bracketed, 57) << "at least 95 % of 60";
  // The key-image cache was written into the map; the next run reads it.
  EXPECT_TRUE(fs::exists(LabMap() / kLocalizationCacheFileName));
  ASSERT_EQ(
      RunVmap("localize " + Quote(LabMap()) + " " + Quote(Shared() / "data/lab_floor/lab_floor.mp4") + " --last 3",
              &out),
      0)
      << out;
  EXPECT_NE(out.find("cache: hit"), std::string::npos) << out;
}

TEST(LocalizeCli, ASingleImageIsRelocalized) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  FrameSourceOptions options;
  options.first = 150;
  options.last = 150;
  const auto source = OpenFrameSource((Shared() / "data/lab_floor/lab_floor.mp4").string(), options);
  const auto frame = source->Next();
  ASSERT_TRUE(frame);
  const fs::path image = tmp.path() / "query.png";
  ASSERT_TRUE(cv::imwrite(image.string(), frame->color));
  std::string out;
  const fs::path json = tmp.path() / "one.json";
  ASSERT_EQ(RunVmap("localize " + Quote(LabMap()) + " " + Quote(image) + " --json " + Quote(json), &out), 0) << out;
  EXPECT_NE(out.find("status          relocalized"), std::string::npos) << out;
  const auto doc = nlohmann::json::parse(std::ifstream(json));
  ASSERT_EQ(doc["frames"].size(), 1u);
  const auto [before, after] = KeysAround(ReadMap(LabMap()), 150);
  const int key = doc["frames"][0]["key"].get<int>();
  EXPECT_TRUE(key == before || key == after) << "key " << key << ", expected " << before << " or " << after;
  // `vmap build` still refuses a single image: one frame makes no map.
  EXPECT_EQ(RunVmap("build " + Quote(image) + " -o " + Quote(tmp.path() / "m"), &out), 2) << out;
}

TEST(LocalizeCli, ADifferentSceneDoesNotLocalize) {
  // desk.mp4 films a desk, not the lab floor: no frame may be localized against the lab-floor map.
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  const fs::path json = tmp.path() / "desk.json";
  // By either acceptance rule: the default (chance) and counts.
  for (const std::string rule : {"counts", "chance"}) {
    ASSERT_EQ(RunVmap("localize " + Quote(LabMap()) + " " + Quote(Shared() / "data/lab_floor/desk.mp4") +
                          " --last 59 --stride 3 -q --acceptance " + rule + " --json " + Quote(json),
                      &out),
              0)
        << out;
    const auto doc = nlohmann::json::parse(std::ifstream(json));
    EXPECT_EQ(doc["summary"]["frames"], 20);
    EXPECT_EQ(doc["summary"]["lost"], 20);
    for (const auto& frame : doc["frames"]) {
      EXPECT_EQ(frame["key"], -1);
      EXPECT_EQ(frame["candidates"].size(), 5u) << "every lost frame verified the best-ranked key images";
      for (const auto& candidate : frame["candidates"]) {
        // Unmatched (null), or matched with a verified set that chance explains.
        if (!candidate["log10_nfa"].is_null()) {
          EXPECT_GT(candidate["log10_nfa"].get<double>(), 0.0) << candidate;
        }
      }
    }
    EXPECT_EQ(doc["options"]["acceptance"], rule);
  }
}

TEST(LocalizeCli, RouteForwardsAndBackwards) {
  SKIP_WITHOUT_SHARED();
  const VisualMap map = ReadMap(LabMap());
  ASSERT_GE(map.key_images.size(), 4u);
  std::string out;
  ASSERT_EQ(RunVmap("route " + Quote(LabMap()) + " --from 0 --to 3", &out), 0) << out;
  EXPECT_NE(out.find("keys            0 1 2 3\n"), std::string::npos) << out;
  EXPECT_NE(out.find("| forwards |"), std::string::npos) << out;
  ASSERT_EQ(RunVmap("route " + Quote(LabMap()) + " --from 3 --to 1", &out), 0) << out;
  EXPECT_NE(out.find("keys            3 2 1\n"), std::string::npos) << out;
  EXPECT_NE(out.find("| backwards |"), std::string::npos) << out;
  // Each step says whether the link's translation can be trusted, backwards as forwards.
  EXPECT_NE(out.find("| translation |"), std::string::npos) << out;
  const bool with_pose = map.links[1].has_pose;
  EXPECT_NE(out.find(!with_pose                       ? "| no pose |"
                     : map.links[1].translation_known ? "| known ("
                                                      : "| unknown: rotation only ("),
            std::string::npos)
      << out;
  ASSERT_EQ(RunVmap("route " + Quote(LabMap()) + " --from 0 --to 99", &out), 2) << out;
  EXPECT_NE(out.find("key image 99 does not exist"), std::string::npos) << out;
  // A localization that follows the route backwards.
  ASSERT_EQ(RunVmap("localize " + Quote(LabMap()) + " " + Quote(Shared() / "data/lab_floor/lab_floor.mp4") +
                        " --from 3 --to 0 --last 5",
                    &out),
            0)
      << out;
}

TEST(LocalizeCli, ReportOfARun) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  const fs::path json = tmp.path() / "run.json";
  ASSERT_EQ(RunVmap("localize " + Quote(LabMap()) + " " + Quote(Shared() / "data/lab_floor/lab_floor.mp4") +
                        " --last 99 --stride 5 -q --json " + Quote(json),
                    &out),
            0)
      << out;
  ASSERT_EQ(RunVmap("report " + Quote(json), &out), 0) << out;
  const fs::path report = tmp.path() / "run_report";
  ASSERT_TRUE(fs::exists(report / kReportFileName)) << out;
  std::ifstream in(report / kReportFileName);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("id=\"key-plot\""), std::string::npos);
  EXPECT_NE(html.find("id=\"localization-similarity-plot\""), std::string::npos);
  EXPECT_NE(html.find("id=\"belief-plot\""), std::string::npos) << "the belief over the route over time";
  int pictures = 0;
  for (const auto& entry : fs::directory_iterator(report / "report/frames")) {
    const cv::Mat image = cv::imread(entry.path().string());
    EXPECT_FALSE(image.empty()) << entry.path();
    ++pictures;
  }
  EXPECT_EQ(pictures, 8);
  // A file that is not a run is refused with a message.
  EXPECT_EQ(RunVmap("report " + Quote(LabMap() / "map.json"), &out), 2) << out;
  EXPECT_NE(out.find("is not a localization run"), std::string::npos) << out;
}

TEST(LocalizeCli, EvalCorridorRuns) {
  // The owners judge ../shared/eval/pepper_corridor as a repeat run against a teach run not here: only check
  // that its 320x240 grey PNGs go through (a map of its even frames, its odd frames localized).
  const fs::path corridor = Shared() / "eval/pepper_corridor/images";
  if (Shared().empty() || !fs::exists(corridor)) GTEST_SKIP() << "../shared/eval/pepper_corridor is not present";
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(corridor) + " --stride 2 --last 99 -q -o " + Quote(tmp.path() / "map"), &out), 0)
      << out;
  const fs::path csv = tmp.path() / "run.csv";
  ASSERT_EQ(RunVmap("localize " + Quote(tmp.path() / "map") + " " + Quote(corridor) +
                        " --first 1 --stride 2 --last 99 -q --csv " + Quote(csv),
                    &out),
            0)
      << out;
  EXPECT_EQ(Lines(csv).size(), 51u);
}

// corridor_conditions' first `last` + 1 repeat frames against an ORB map of its teach run, once per entry of `flags`
// (more flags for vmap localize): each frame's status and key image (with `teach_frames`: the key image's frame in
// the teach run, the CSV's key_frame). With `repeat_frames`, those repeat frames in that order instead, as one run (a
// robot carried along the route; `last` unused). Empty without the data.
std::vector<std::vector<std::pair<std::string, int>>> CorridorRuns(const std::vector<std::string>& flags, int last,
                                                                   bool teach_frames = false,
                                                                   const std::vector<int>& repeat_frames = {}) {
  const fs::path data = Shared() / "data/corridor_conditions";
  if (Shared().empty() || !fs::exists(data)) return {};
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  EXPECT_EQ(RunVmap("build " + Quote(data / "teach") + " -q -o " + Quote(tmp.path() / "map"), &out), 0) << out;
  std::string query = Quote(data / "repeat") + " --last " + std::to_string(last);
  if (!repeat_frames.empty()) {
    const fs::path folder = tmp.path() / "carried";
    fs::create_directories(folder);
    for (size_t i = 0; i < repeat_frames.size(); ++i) {
      char name[32], link[32];
      std::snprintf(name, sizeof(name), "%07d.jpg", repeat_frames[i]);
      std::snprintf(link, sizeof(link), "%07zu.jpg", i);
      fs::create_symlink(data / "repeat" / name, folder / link);
    }
    query = Quote(folder);
  }
  std::vector<std::vector<std::pair<std::string, int>>> runs;
  for (const std::string& f : flags) {
    const fs::path csv = tmp.path() / "run.csv";
    EXPECT_EQ(RunVmap("localize " + Quote(tmp.path() / "map") + " " + query + " -q --csv " + Quote(csv) + f, &out), 0)
        << out;
    const std::vector<std::string> status = CsvColumn(csv, "status"),
                                   keys = CsvColumn(csv, teach_frames ? "key_frame" : "key");
    std::vector<std::pair<std::string, int>> frames;
    for (size_t i = 0; i < status.size() && i < keys.size(); ++i) frames.emplace_back(status[i], std::stoi(keys[i]));
    runs.push_back(std::move(frames));
  }
  return runs;
}

// Tests of a step back or of guided matching on the corridor measure them without the heading's acceptance, which
// accepts some of the frames they probe (frames 96-97 tracked at key image 39 either way: docs/localize.md, "A heading
// that stands out against the frame's rivals").
const std::string kWithoutHeading = " --min-heading-rival-ratio 0";

// A frame placed on the route (tracking or relocalized), as bench/route_conditions.py counts it: where the goals ask
// the frame to be. A frame the agreement of its ranking and its heading places is placed but not steered by (guidance
// "none": AFrameTheEvidenceStepsOnIsNotSteeredByItsHeading); the counts below are of placed frames.
bool Placed(const std::pair<std::string, int>& frame) {
  return frame.first == "tracking" || frame.first == "relocalized";
}

// How many times a run's placed frames go back to an earlier key image (or its teach frame).
int BackJumps(const std::vector<std::pair<std::string, int>>& run) {
  int jumps = 0, placed_key = -1;
  for (const auto& frame : run) {
    if (!Placed(frame)) continue;
    jumps += frame.second < placed_key;
    placed_key = frame.second;
  }
  return jumps;
}

// As CorridorRuns, how many times each run's placed frames go back to an earlier key image.
std::vector<int> BackJumpsOnCorridor(const std::vector<std::string>& flags, int last) {
  std::vector<int> back_jumps;
  for (const auto& run : CorridorRuns(flags, last)) back_jumps.push_back(BackJumps(run));
  return back_jumps;
}

// As CorridorRuns, how many frames are placed (tracking or relocalized) in each run.
std::vector<int> PlacedOnCorridor(const std::vector<std::string>& flags, int last = 39) {
  std::vector<int> placed;
  for (const auto& run : CorridorRuns(flags, last)) {
    placed.push_back(static_cast<int>(std::count_if(run.begin(), run.end(), Placed)));
  }
  return placed;
}

TEST(LocalizeCli, GuidedMatchingTracksFramesChanceRefusedAcrossLighting) {
  // corridor_conditions with ORB (docs/localize.md, "Guided matching by the belief"): frames whose cross-checked
  // matches verify too few at the tracked key images for chance while the belief holds them there are matched
  // again with those key images only, one-way best matches kept, and the a-contrario test accepts some of them
  // (the continuity of the heading and the window off, to see guided matching's own).
  const std::vector<int> placed =
      PlacedOnCorridor({" --continuity-share 0 --no-window-matching", " --no-guided-matching"});
  if (placed.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_GE(placed[0], placed[1] + 4) << "guided " << placed[0] << ", without " << placed[1];
}

TEST(LocalizeCli, TheHeadingsContinuityTracksGuidedFramesChanceRefuses) {
  // corridor_conditions with ORB (docs/localize.md, "Continuity of the heading"): a guided comparison chance refuses
  // is accepted when its matches move as the previous frame's heading against the key image predicts.
  const std::vector<int> placed =
      PlacedOnCorridor({" --no-window-matching", " --continuity-share 0 --no-window-matching"});
  if (placed.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_GE(placed[0], placed[1] + 4) << "with the continuity " << placed[0] << ", without " << placed[1];
}

TEST(LocalizeCli, AStartKeyTracksTheRepeatRunsFirstFrames) {
  // corridor_conditions with ORB (docs/localize.md, "The start"): the repeat run starts where the teach run did;
  // started there, the belief singles that place out and guided matching asks there on the first frames.
  const std::vector<int> placed = PlacedOnCorridor({" --start-key 0", ""});
  if (placed.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_GE(placed[0], placed[1] + 2) << "started at key image 0 " << placed[0] << ", anywhere " << placed[1];
}

// Of a corridor run from repeat frame `first` (CorridorRuns with teach frames): its frames placed more than 8 teach
// frames from their own (far) and those within 8 (near).
std::pair<int, int> PlacedFarAndNear(const std::vector<std::pair<std::string, int>>& run, int first) {
  int far = 0, near = 0;
  for (size_t i = 0; i < run.size(); ++i) {
    if (!Placed(run[i])) continue;
    const int repeat_frame = first + static_cast<int>(i);  // at teach frame repeat_frame
    (std::abs(run[i].second - repeat_frame) > 8 ? far : near) += 1;
  }
  return {far, near};
}

TEST(LocalizeCli, AStartKeyIsAHintARunStartedElsewhereOverrides) {
  // corridor_conditions with ORB from repeat frame 20, started with --start-key 0 as a user does by habit
  // (docs/localize.md, "The start is a hint"): the start's prior alone steered frames 23-25 by key images 1-2 (teach
  // frames 2-5) and lost the frames after them; checked over the route, the frames find teach frames 20 on. Measured
  // as when it was chosen, without ORB's ranking weighed: the ranking of the frames checked over the route finds the
  // place too (10 frames steered by near their place, 0 far, with the hint or without). With the defaults: none far,
  // as many near as the hint alone. Nor a lost frame's relocalization matched guided (--no-guided-relocalization),
  // which relocalizes frames 22-24 near their place with the hint or without.
  const std::string alone = " --start-key 0 --first 20 --no-rank-evidence --no-guided-relocalization";
  const auto runs = CorridorRuns({alone, alone + " --no-start-is-hint", " --start-key 0 --first 20"}, 33, true);
  if (runs.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  const auto [far, near] = PlacedFarAndNear(runs[0], 20);
  const auto [prior_far, prior_near] = PlacedFarAndNear(runs[1], 20);
  EXPECT_LT(far, prior_far) << "placed far from their place: a hint " << far << ", a prior " << prior_far;
  EXPECT_GE(near, prior_near + 4) << "placed near their place: a hint " << near << ", a prior " << prior_near;
  const auto [default_far, default_near] = PlacedFarAndNear(runs[2], 20);
  EXPECT_EQ(default_far, 0);
  EXPECT_GE(default_near, near) << "placed near their place: the defaults " << default_near << ", the hint alone "
                                << near;
}

TEST(LocalizeCli, AStartKeyNeedsTheFramesEvidence) {
  // corridor_conditions with ORB from repeat frame 20, started with --start-key 0 (docs/localize.md, "The start needs
  // the frames' evidence"): before the start was confirmed, frame 23 verified key image 1 (teach frame 4) by chance
  // (log10 NFA -1.1) while the frames' evidence alone held 0.04 of its belief near it, less than a flat belief; the
  // start's prior alone made it confident, and it was steered by 19 teach frames off. Measured as when it was chosen,
  // without ORB's ranking weighed (with it frame 23 is uncertain at key image 9, its place, whether the rule is on or
  // off), nor a lost frame's relocalization matched guided (--no-guided-relocalization, as above), nor the comparisons
  // away from the tracker verified with fewer iterations (--far-comparison-iterations 0: with them no frame is placed
  // far without the rule either). With the defaults: none far.
  const std::string alone =
      " --start-key 0 --first 20 --no-rank-evidence --no-guided-relocalization --far-comparison-iterations 0";
  const auto runs = CorridorRuns({alone, alone + " --no-start-needs-evidence", " --start-key 0 --first 20"}, 33, true);
  if (runs.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  const int far = PlacedFarAndNear(runs[0], 20).first, prior_far = PlacedFarAndNear(runs[1], 20).first;
  EXPECT_LT(far, prior_far) << "placed far from their place: with the evidence " << far << ", without " << prior_far;
  EXPECT_EQ(PlacedFarAndNear(runs[2], 20).first, 0);
}

TEST(LocalizeCli, OrbsRankingWeighsTheBeliefOfTheFramesAfterIt) {
  // corridor_conditions with ORB (docs/localize.md, "ORB's ranking only withholds its own frame"): the dark frames
  // 40-42 were lost or uncertain at key image 15 on the comparisons alone; the rankings of the frames that were ranked
  // weigh the belief (by how far each key image's votes stand out, after the frame's own moves), and frames 41-42 are
  // tracked at key image 15, their place. None is steered by far from its place either way.
  const auto runs = CorridorRuns({"", " --no-rank-evidence"}, 45, true);
  if (runs.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  const auto [far, near] = PlacedFarAndNear(runs[0], 0);
  const auto [alone_far, alone_near] = PlacedFarAndNear(runs[1], 0);
  EXPECT_EQ(far, 0);
  EXPECT_EQ(alone_far, 0);
  EXPECT_GE(near, alone_near + 2) << "placed near their place: the ranking weighed " << near << ", not " << alone_near;
}

TEST(LocalizeCli, AFrameVerifiedWhereItsRankingPutsItIsSteeredBy) {
  // corridor_conditions with ORB (docs/localize.md, "A frame verified where its ranking puts it"): frame 47 is
  // relocalized a frame after its key image stopped verifying, and its comparison passes chance where the belief with
  // its ranking singles the place out; the belief before its ranking, still at the key image left, doubted it. The rule
  // changes nothing else: each frame it changes is one the belief doubted, now steered by at the same key image, and
  // nothing is steered by far from its place or back.
  const auto runs = CorridorRuns({"", " --no-verified-ranking-steers"}, 49, true);
  if (runs.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  ASSERT_EQ(runs[0].size(), runs[1].size());
  int released = 0;
  for (size_t i = 0; i < runs[0].size(); ++i) {
    if (runs[0][i] == runs[1][i]) continue;
    EXPECT_EQ(runs[1][i].first, "uncertain") << "frame " << i;
    EXPECT_TRUE(Placed(runs[0][i])) << "frame " << i << ": " << runs[0][i].first;
    EXPECT_EQ(runs[0][i].second, runs[1][i].second) << "frame " << i;
    ++released;
  }
  EXPECT_GE(released, 1) << "no doubted frame placed";
  EXPECT_EQ(PlacedFarAndNear(runs[0], 0).first, 0);
  EXPECT_LE(BackJumps(runs[0]), BackJumps(runs[1]));
}

TEST(LocalizeCli, MatchingInTheWindowOfThePredictionTracksFramesTheContinuityMisses) {
  // corridor_conditions with ORB (docs/localize.md, "Matching guided by the prediction"): a guided comparison neither
  // chance nor the continuity of the heading accepts is matched again only around the previous frame's heading
  // against the key image, and accepted by that matching's own measured threshold (frames 80 and 81). Guided matching
  // asks the key image and the next only, as when the window was measured (over the lookahead, 2026-11-29, the two
  // runs steered by 66 and 65 of the first 86 frames), and a lost frame is not compared again with more features (one
  // of the frames the window tracks is relocalized so without the window: docs/measurements/
  // localization-conditions.md, "A lost frame compared again with more features").
  const std::vector<int> placed =
      PlacedOnCorridor({" --no-guided-lookahead --lost-frame-features 0",
                        " --no-window-matching --no-guided-lookahead --lost-frame-features 0"},
                       85);
  if (placed.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_GE(placed[0], placed[1] + 2) << "with the window " << placed[0] << ", without " << placed[1];
}

TEST(LocalizeCli, AStepBackOnTheEdgeOfChanceIsNotTaken) {
  // corridor_conditions with ORB (docs/localize.md, "A step back needs more than chance"): frame 96 verifies nothing
  // at its key image and the two ahead, and the key image behind at log10 NFA -0.05; at chance's own bar (0) the
  // tracker steps back to it, one more frame steered by behind the frame before it.
  const std::vector<int> back_jumps =
      BackJumpsOnCorridor({kWithoutHeading, kWithoutHeading + " --step-back-max-log10-nfa 0"}, 99);
  if (back_jumps.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_LT(back_jumps[0], back_jumps[1]) << "back-jumps: -1 " << back_jumps[0] << ", 0 " << back_jumps[1];
}

TEST(LocalizeCli, AStepBackOnATieIsNotTaken) {
  // corridor_conditions with ORB (docs/localize.md, "A step back needs more than a tie"): at frame 17 the key image
  // behind verifies as many matches as the tracked one and S took the tracker back, one more frame steered by behind
  // the frame before it. Measured as when it was chosen, without "a step back or on needs a lower NFA too", which holds
  // frames 16-17 at key image 4 before the tie arises.
  const std::string count = " --step-back-on-count --step-on-on-count";
  const std::vector<int> back_jumps = BackJumpsOnCorridor({count, count + " --step-back-on-tie"}, 20);
  if (back_jumps.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_LT(back_jumps[0], back_jumps[1])
      << "back-jumps: needs more " << back_jumps[0] << ", on a tie " << back_jumps[1];
}

TEST(LocalizeCli, AStepBackWhoseMatchesChanceExplainsBetterIsNotTaken) {
  // corridor_conditions with ORB (docs/localize.md, "A step back or on needs a lower NFA too"): at frame 57 the key
  // image behind verifies 27 matches at log10 NFA -3.6 against the tracked key image's 26 at -12.1, and the count alone
  // took the tracker back, a frame steered by behind the frame before it.
  const std::vector<int> back_jumps =
      BackJumpsOnCorridor({kWithoutHeading, kWithoutHeading + " --step-back-on-count"}, 60);
  if (back_jumps.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_LT(back_jumps[0], back_jumps[1])
      << "back-jumps: needs a lower NFA " << back_jumps[0] << ", on the count " << back_jumps[1];
}

TEST(LocalizeCli, AStepOnWhoseMatchesChanceExplainsBetterIsNotTakenWithOrb) {
  // corridor_conditions with ORB (docs/localize.md, "A step back or on needs a lower NFA too"): at frame 103 the key
  // image ahead verifies 23 matches at log10 NFA -8.5 against the tracked key image's 22 at -15.8; the count alone took
  // the tracker on, a teach frame early, and a frame after it stepped back. Measured as when it was chosen, without "a
  // step on is earned, so a step back is not needed", which now holds that step on or undoes the step back after it.
  const std::string before = " --no-hold-unearned-step-on --no-step-back-needs-belief";
  const std::vector<int> back_jumps = BackJumpsOnCorridor({before, before + " --step-on-on-count"}, 110);
  if (back_jumps.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  EXPECT_LT(back_jumps[0], back_jumps[1])
      << "back-jumps: needs a lower NFA " << back_jumps[0] << ", on the count " << back_jumps[1];
}

TEST(LocalizeCli, GuidedMatchingOverTheLookaheadKeepsUpWithTheRobot) {
  // corridor_conditions with ORB (docs/localize.md, "Guided matching over the lookahead"): repeat frame i was taken
  // where teach frame i was. Where the repeat passes a key image a frame (frames 97-99) guided matching asked only the
  // tracked key image and the next, and the continuity of the heading held the frames at key image 38 (teach frame 91);
  // asked over the lookahead and ranked by the one-way matches' NFA, they are steered by at key images within 3 teach
  // frames of them.
  const auto runs =
      CorridorRuns({kWithoutHeading, kWithoutHeading + " --no-guided-lookahead"}, 99, /*teach_frames=*/true);
  if (runs.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  std::vector<int> near;
  for (const auto& run : runs) {
    int count = 0;
    for (size_t i = 0; i < run.size(); ++i)
      count += Placed(run[i]) && std::abs(run[i].second - static_cast<int>(i)) <= 3;
    near.push_back(count);
  }
  EXPECT_GE(near[0], near[1] + 2) << "within 3 teach frames: over the lookahead " << near[0] << ", not " << near[1];
}

TEST(LocalizeCli, GuidedMatchingAsksWhereTheEstimateWasDroppedWhileLost) {
  // corridor_conditions with ORB (docs/localize.md, "Guided matching while lost"): nothing verifies on frames 36-41,
  // the estimate is dropped and the belief flattens; frame 43's guided comparison with key image 16, where the
  // tracker held the frames, is accepted and steered by. Measured as when it was chosen, without ORB's ranking weighed:
  // with it frames 41-42 are tracked at key image 15 and the estimate is not dropped. With the defaults: none steered
  // by far from its place, as many steered by as the rule alone.
  const auto runs = CorridorRuns({" --no-rank-evidence", " --no-rank-evidence --no-guided-while-lost", ""}, 45, true);
  if (runs.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  std::vector<int> placed;
  for (const auto& run : runs) placed.push_back(static_cast<int>(std::count_if(run.begin(), run.end(), Placed)));
  EXPECT_GE(placed[0], placed[1] + 1) << "asked while lost " << placed[0] << ", not " << placed[1];
  EXPECT_EQ(PlacedFarAndNear(runs[2], 0).first, 0);
  EXPECT_GE(placed[2], placed[0]) << "placed: the defaults " << placed[2] << ", the rule alone " << placed[0];
}

TEST(LocalizeCli, AFarPlaceALostFrameVerifiedIsAskedAgain) {
  // corridor_conditions with ORB (docs/localize.md, "A rival place is asked again while the frames are not steered
  // by"): repeat frames 30-50 and then 80-95 as one run, the robot carried 30 frames on. After the jump nothing
  // verifies where the tracker holds the frames; the run's frame 25 (repeat frame 84) verifies key image 36, a far
  // place one frame does not move the tracker to, and the ranking did not bring it back on the frames after it. Asked
  // again, its evidence moves the belief and the tracker there two frames later; without it the frames stay uncertain
  // until the estimate is dropped (repeat frame 93). Measured as when it was chosen, without ORB's ranking weighed (the
  // rankings of the frames after the jump bring the belief there too).
  std::vector<int> repeat_frames;
  for (int i = 30; i <= 50; ++i) repeat_frames.push_back(i);
  for (int i = 80; i <= 95; ++i) repeat_frames.push_back(i);
  const std::string alone = " --start-key 10 --no-rank-evidence";
  const auto runs = CorridorRuns({alone, alone + " --no-rival-place-when-not-steered", " --start-key 10"}, 0,
                                 /*teach_frames=*/true, repeat_frames);
  if (runs.empty()) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  std::vector<int> near(3, 0), far(3, 0);
  for (int r = 0; r < 3; ++r) {
    for (size_t i = 21; i < runs[r].size(); ++i) {  // the frames after the jump
      if (!Placed(runs[r][i])) continue;
      (std::abs(runs[r][i].second - repeat_frames[i]) <= 5 ? near : far)[r] += 1;
    }
  }
  EXPECT_EQ(far[0], 0);
  EXPECT_GE(near[0], near[1] + 4) << "placed near their place: asked again " << near[0] << ", not " << near[1];
  // With the defaults: none far, as many near as the rule alone.
  EXPECT_EQ(far[2], 0);
  EXPECT_GE(near[2], near[0]) << "placed near their place: the defaults " << near[2] << ", the rule alone " << near[0];
}

// michigan_seasons' images (`names`: "SSPP", session SS's place PP) linked into `folder` as frames 1.png, 2.png, ...
fs::path MichiganFrames(const fs::path& folder, const std::vector<std::string>& names) {
  fs::create_directories(folder);
  for (size_t i = 0; i < names.size(); ++i) {
    fs::create_symlink(Shared() / "data/michigan_seasons/images" / (names[i] + ".png"),
                       folder / (std::to_string(i + 1) + ".png"));
  }
  return folder;
}

// Session `s`'s five places, in route order.
fs::path MichiganSession(const fs::path& folder, int s) {
  std::vector<std::string> names;
  for (int place = 1; place <= 5; ++place) {
    char name[8];
    std::snprintf(name, sizeof(name), "%02d%02d", s, place);
    names.push_back(name);
  }
  return MichiganFrames(folder, names);
}

// Session `s`'s --tau 1 map in `dir`: one key image a place.
fs::path MichiganMap(const fs::path& dir, int s) {
  const fs::path map = dir / ("map" + std::to_string(s));
  std::string out;
  EXPECT_EQ(RunVmap("build " + Quote(MichiganSession(dir / ("map_session" + std::to_string(s)), s)) + " -o " +
                        Quote(map) + " --tau 1 -q",
                    &out),
            0)
      << out;
  return map;
}

// The sessions' five places each, in `dir`.
std::vector<fs::path> MichiganSessions(const fs::path& dir, const std::vector<int>& sessions) {
  std::vector<fs::path> folders;
  for (int s : sessions) folders.push_back(MichiganSession(dir / ("session" + std::to_string(s)), s));
  return folders;
}

// `query` localized against `map` from key image `start_key` with `flags`: how many frames are placed at the key
// image `key_of(frame)` and how many elsewhere.
std::pair<int, int> PlacedAtAndElsewhere(const fs::path& map, const fs::path& query, int start_key,
                                         const std::string& flags, const std::function<int(int)>& key_of,
                                         const fs::path& csv) {
  std::pair<int, int> counts = {0, 0};
  std::string out;
  EXPECT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(query) + " --start-key " + std::to_string(start_key) +
                        " -q --csv " + Quote(csv) + flags,
                    &out),
            0)
      << out;
  const std::vector<std::string> frames = CsvColumn(csv, "frame"), status = CsvColumn(csv, "status"),
                                 keys = CsvColumn(csv, "key");
  for (size_t i = 0; i < frames.size(); ++i) {
    if (!Placed({status[i], 0})) continue;
    (std::stoi(keys[i]) == key_of(std::stoi(frames[i])) ? counts.first : counts.second) += 1;
  }
  return counts;
}

// Each query session's frame i, taken at key image i's place, against `map` from key image 0: frames placed at
// their place and elsewhere, over the sessions.
std::pair<int, int> PlacedOnMichiganRoutes(const fs::path& map, const std::vector<fs::path>& queries,
                                           const std::string& flags, const fs::path& csv) {
  std::pair<int, int> counts = {0, 0};
  for (const fs::path& query : queries) {
    const std::pair<int, int> run = PlacedAtAndElsewhere(
        map, query, 0, flags, [](int frame) { return frame; }, csv);
    counts.first += run.first;
    counts.second += run.second;
  }
  return counts;
}

// michigan_seasons as a route (docs/localize.md, "A heading that stands out against the frame's rivals"): a --tau 1
// map of session 01's five places, another session's five localized against it from key image 0. Across seasons chance
// refuses ORB's verified sets at most right key images, but their matches agree on one displacement (the heading
// mode) far more than another place's do: frames that stand out so are steered by at their place, none elsewhere.
TEST(LocalizeCli, AHeadingThatStandsOutAgainstTheFramesRivalsLocalizesAcrossSeasons) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = MichiganMap(tmp.path(), 1);
  const std::vector<fs::path> queries = MichiganSessions(tmp.path(), {2, 5, 7, 9, 11});
  const fs::path csv = tmp.path() / "run.csv";
  // Measured as the rule was chosen, without the lost frames' comparisons with more features (some of the frames it
  // accepts verify with them: ALostFrameComparedAgainWithMoreFeaturesIsRelocalized); with the defaults, none placed
  // elsewhere.
  const std::string before = " --lost-frame-features 0";
  const std::pair<int, int> with = PlacedOnMichiganRoutes(map, queries, before, csv),
                            without =
                                PlacedOnMichiganRoutes(map, queries, before + " --min-heading-rival-ratio 0", csv);
  EXPECT_GE(with.first, without.first + 4) << "with the heading " << with.first << ", without " << without.first;
  EXPECT_EQ(with.second, 0) << "placed at another place";
  EXPECT_EQ(PlacedOnMichiganRoutes(map, queries, "", csv).second, 0) << "with the defaults, placed elsewhere";
}

// A lost frame steps on where its ranking and its heading agree (docs/measurements/localization-conditions.md): the
// same map, sessions whose frames nothing verifies, relocalized or guided, at a place or two, and whose ranking and
// heading modes both name the tracker's next key image there: placed at their place, none elsewhere (placed, not
// steered by: AFrameTheEvidenceStepsOnIsNotSteeredByItsHeading).
TEST(LocalizeCli, ALostFrameStepsOnWhereItsRankingAndItsHeadingAgree) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = MichiganMap(tmp.path(), 1);
  const std::vector<fs::path> queries = MichiganSessions(tmp.path(), {4, 6, 7, 9, 12});
  const fs::path csv = tmp.path() / "run.csv";
  // Measured as the rule was chosen, without the lost frames' comparisons with more features (some of its frames verify
  // with them: ALostFrameComparedAgainWithMoreFeaturesIsRelocalized); with the defaults, none placed elsewhere.
  const std::string before = " --lost-frame-features 0";
  const std::pair<int, int> with = PlacedOnMichiganRoutes(map, queries, before, csv),
                            without = PlacedOnMichiganRoutes(map, queries,
                                                             before + " --no-step-on-where-evidence-agrees", csv);
  EXPECT_GE(with.first, without.first + 4) << "with the rule " << with.first << ", without " << without.first;
  EXPECT_EQ(with.second, 0) << "placed at another place";
  EXPECT_EQ(PlacedOnMichiganRoutes(map, queries, "", csv).second, 0) << "with the defaults, placed elsewhere";
}

// The frames the rule above places have no heading to steer by: the heading is that of comparisons chance and the
// heading rule refused (on michigan_seasons a third of them more than 35 px off the hand label). Each frame lost
// without the rule and placed with it reports guidance "none" and no heading; every other frame is reported as before.
TEST(LocalizeCli, AFrameTheEvidenceStepsOnIsNotSteeredByItsHeading) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = MichiganMap(tmp.path(), 1);
  int placed_without_heading = 0;
  for (const fs::path& query : MichiganSessions(tmp.path(), {4, 6, 7, 9, 12})) {
    std::map<std::string, std::map<std::string, std::vector<std::string>>> runs;
    // Measured as the rule was chosen, without the lost frames' comparisons with more features (some of its frames are
    // relocalized by them, with a heading chance accepted); with the defaults, a frame not steered by has no heading.
    for (const std::string flags :
         {" --lost-frame-features 0", " --lost-frame-features 0 --no-step-on-where-evidence-agrees", ""}) {
      const fs::path csv = tmp.path() / "run.csv";
      std::string out;
      ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(query) + " --start-key 0 -q --csv " + Quote(csv) + flags,
                        &out),
                0)
          << out;
      for (const std::string column : {"status", "key", "guidance", "heading_px"})
        runs[flags][column] = CsvColumn(csv, column);
    }
    const auto& with = runs[" --lost-frame-features 0"];
    const auto& without = runs[" --lost-frame-features 0 --no-step-on-where-evidence-agrees"];
    const auto& defaults = runs[""];
    for (size_t i = 0; i < defaults.at("status").size(); ++i) {
      if (defaults.at("guidance")[i] == "none") {
        EXPECT_EQ(defaults.at("heading_px")[i], "") << "defaults, frame " << i;
      }
    }
    ASSERT_EQ(with.at("status").size(), without.at("status").size());
    for (size_t i = 0; i < with.at("status").size(); ++i) {
      const std::string frame = query.filename().string() + " frame " + std::to_string(i);
      if (without.at("status")[i] == "lost" && Placed({with.at("status")[i], 0})) {
        EXPECT_EQ(with.at("guidance")[i], "none") << frame;
        EXPECT_EQ(with.at("heading_px")[i], "") << frame;
        ++placed_without_heading;
      } else if (with.at("key")[i] == without.at("key")[i] && with.at("status")[i] == without.at("status")[i]) {
        EXPECT_EQ(with.at("guidance")[i], without.at("guidance")[i]) << frame;
      }
    }
  }
  EXPECT_GE(placed_without_heading, 4);
}

// The same after lost frames (docs/measurements/localization-conditions.md, "A frame after lost frames steps on where
// its evidence agrees"): session 11's map, sessions whose first frame nothing verifies at the start key image and
// whose second frame's ranking and heading name key image 1 where the first frame's did not: placed at their place
// (not steered by: guidance "none", no heading), none elsewhere; lost without the rule.
TEST(LocalizeCli, AFrameAfterLostFramesStepsOnWhereItsEvidenceAgrees) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = MichiganMap(tmp.path(), 11);
  const std::vector<fs::path> queries = MichiganSessions(tmp.path(), {1, 2, 3, 6, 10});
  const fs::path csv = tmp.path() / "run.csv";
  // Measured as the rule was chosen, without a lost frame's heading with more features (it places one of these frames
  // without the rule: ALostFramesHeadingWithMoreFeaturesPlacesIt); with the defaults, none placed elsewhere.
  const std::string before = " --no-lost-frame-heading";
  const std::pair<int, int> without =
      PlacedOnMichiganRoutes(map, queries, before + " --no-step-on-after-lost-frames", csv);
  const std::pair<int, int> with = PlacedOnMichiganRoutes(map, queries, before, csv);
  EXPECT_GE(with.first, without.first + 2) << "with the rule " << with.first << ", without " << without.first;
  EXPECT_EQ(with.second, 0) << "placed at another place";
  EXPECT_EQ(PlacedOnMichiganRoutes(map, queries, "", csv).second, 0) << "with the defaults, placed elsewhere";
  std::string out;
  ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(queries[1]) + " --start-key 0 -q --csv " + Quote(csv), &out),
            0)
      << out;
  EXPECT_EQ(CsvColumn(csv, "status")[1], "tracking");
  EXPECT_EQ(CsvColumn(csv, "key")[1], "1");
  EXPECT_EQ(CsvColumn(csv, "guidance")[1], "none");
  EXPECT_EQ(CsvColumn(csv, "heading_px")[1], "");
}

// The rule above needs the frame's own evidence, not the motion prior: a robot that stops at a place, whose frames
// nothing verifies, is not walked on to the next key image. Session 12's map, from key image 2 (place 3): the place-3
// images of sessions 02 and 06 repeated (their ranking and heading name place 4: stepped on from the start key image by
// a rule that does not ask for a frame steered by before it), and session 12's own place-3 image, steered by, then
// those of sessions 01 and 05 (stepped on by a rule that asks no evidence of the frame). Six of michigan's 660 place
// images name the next place so and are stepped on once after a steered frame (docs/measurements/
// localization-conditions.md, "A lost frame steps on where its ranking and its heading agree").
TEST(LocalizeCli, ALostFrameOfARobotThatStopsIsNotSteppedOn) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = MichiganMap(tmp.path(), 12);
  const fs::path csv = tmp.path() / "run.csv";
  const std::vector<std::vector<std::string>> stops = {std::vector<std::string>(5, "0203"),
                                                       std::vector<std::string>(5, "0603"),
                                                       {"1203", "0103", "0103", "0103", "0103"},
                                                       {"1203", "0503", "0503", "0503", "0503"}};
  for (const std::vector<std::string>& frames : stops) {
    const fs::path query = MichiganFrames(tmp.path() / (frames.front() + "_" + frames.back()), frames);
    const std::pair<int, int> run = PlacedAtAndElsewhere(
        map, query, 2, "", [](int) { return 2; }, csv);
    EXPECT_EQ(run.second, 0) << frames.front() << ", then " << frames.back() << ": steered by at another place";
  }
}

// A lost frame compared again with more features (docs/measurements/localization-conditions.md, "A lost frame compared
// again with more features"): session 6's map, sessions with frames that verify nothing with the map's 500 features at
// any key image, and whose right key image's comparison with more features on both sides passes chance: relocalized at
// their place, none elsewhere; lost without it. Session 1's frame 1 (place 2) is one.
TEST(LocalizeCli, ALostFrameComparedAgainWithMoreFeaturesIsRelocalized) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = MichiganMap(tmp.path(), 6);
  const std::vector<fs::path> queries = MichiganSessions(tmp.path(), {1, 3, 7, 8, 11});
  const fs::path csv = tmp.path() / "run.csv";
  const std::pair<int, int> without = PlacedOnMichiganRoutes(map, queries, " --lost-frame-features 0", csv);
  const std::pair<int, int> with = PlacedOnMichiganRoutes(map, queries, "", csv);
  EXPECT_GE(with.first, without.first + 4) << "with the rule " << with.first << ", without " << without.first;
  EXPECT_EQ(with.second, 0) << "placed at another place";
  for (const std::string flags : {"", " --lost-frame-features 0"}) {
    std::string out;
    ASSERT_EQ(
        RunVmap("localize " + Quote(map) + " " + Quote(queries[0]) + " --start-key 0 -q --csv " + Quote(csv) + flags,
                &out),
        0)
        << out;
    EXPECT_EQ(CsvColumn(csv, "status")[1], flags.empty() ? "relocalized" : "lost") << flags;
    if (flags.empty()) {
      EXPECT_EQ(CsvColumn(csv, "key")[1], "1");
    }
  }
}

// A lost frame's heading with more features (docs/measurements/localization-conditions.md): session 10's map, sessions
// with frames whose comparisons with more features chance refuses at every key image, but whose heading mode stands
// out there against the other key images compared so: placed at their place and steered by (a heading to steer by),
// none elsewhere; lost without it.
TEST(LocalizeCli, ALostFramesHeadingWithMoreFeaturesPlacesIt) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = MichiganMap(tmp.path(), 10);
  const std::vector<fs::path> queries = MichiganSessions(tmp.path(), {2, 5, 6, 9, 12});
  const fs::path csv = tmp.path() / "run.csv";
  const std::pair<int, int> without = PlacedOnMichiganRoutes(map, queries, " --no-lost-frame-heading", csv);
  const std::pair<int, int> with = PlacedOnMichiganRoutes(map, queries, "", csv);
  EXPECT_GE(with.first, without.first + 6) << "with the rule " << with.first << ", without " << without.first;
  EXPECT_EQ(with.second, 0) << "placed at another place";
  int steered_with_heading = 0;
  for (const fs::path& query : queries) {
    std::map<std::string, std::vector<std::string>> runs[2];
    for (const int rule : {0, 1}) {
      std::string out;
      ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(query) + " --start-key 0 -q --csv " + Quote(csv) +
                            (rule ? "" : " --no-lost-frame-heading"),
                        &out),
                0)
          << out;
      for (const std::string column : {"status", "guidance", "heading_px"}) runs[rule][column] = CsvColumn(csv, column);
    }
    for (size_t i = 0; i < runs[1].at("status").size(); ++i) {
      if (runs[0].at("status")[i] != "lost" || !Placed({runs[1].at("status")[i], 0})) continue;
      EXPECT_NE(runs[1].at("guidance")[i], "none") << query.filename() << " frame " << i;
      if (!runs[1].at("heading_px")[i].empty()) ++steered_with_heading;
    }
  }
  EXPECT_GE(steered_with_heading, 6);
}

TEST(LocalizeCli, ComparisonsMadeOnOtherThreadsChangeNoResult) {
  // corridor_conditions with ORB: its frames are refused at their tracked key images, compared with their rivals,
  // relocalized and questioned. The comparisons a frame is about to make are made meanwhile on a second core
  // (LocalizerOptions::comparison_threads; docs/measurements/localization-conditions.md, "Where ORB's corridor time
  // goes"), and the extraction threads compare each frame ahead with the key images the estimate before it was at
  // (LocalizeSequenceOptions::compare_ahead). Every result is as when each comparison is made in turn, bit for bit:
  // the CSV's columns but the time, and the JSON's confidence and belief, whose sums run over the frame's comparisons.
  const fs::path data = Shared() / "data/corridor_conditions";
  if (Shared().empty() || !fs::exists(data)) GTEST_SKIP() << "../shared/data/corridor_conditions is not present";
  ::vmap::testing::ScopedTempDir tmp;
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(data / "teach") + " -q -o " + Quote(tmp.path() / "map"), &out), 0) << out;
  // Per run, each CSV column but the time, by name, and each JSON frame but its time.
  std::vector<std::map<std::string, std::vector<std::string>>> runs;
  std::vector<nlohmann::json> json_frames;
  for (const std::string flags : {"", " --comparison-threads 1", " --comparison-threads 1 --no-compare-ahead"}) {
    const fs::path csv = tmp.path() / "run.csv", json = tmp.path() / "run.json";
    ASSERT_EQ(RunVmap("localize " + Quote(tmp.path() / "map") + " " + Quote(data / "repeat") + " --last 59 -q --csv " +
                          Quote(csv) + " --json " + Quote(json) + flags,
                      &out),
              0)
        << out;
    std::stringstream header(Lines(csv).at(0));
    std::map<std::string, std::vector<std::string>> columns;
    for (std::string name; std::getline(header, name, ',');) {
      if (name != "seconds") columns[name] = CsvColumn(csv, name);
    }
    runs.push_back(std::move(columns));
    std::ifstream in(json);
    nlohmann::json frames = nlohmann::json::parse(in).at("frames");
    for (nlohmann::json& frame : frames) frame.erase("seconds");
    json_frames.push_back(std::move(frames));
  }
  ASSERT_EQ(runs[0].at("status").size(), 60u);
  EXPECT_GT(runs[0].size(), 40u);
  for (size_t r = 1; r < runs.size(); ++r) {
    for (const auto& [name, cells] : runs[0]) EXPECT_EQ(cells, runs[r].at(name)) << "run " << r << ": " << name;
    ASSERT_EQ(json_frames[0].size(), json_frames[r].size());
    for (size_t f = 0; f < json_frames[0].size(); ++f) {
      EXPECT_EQ(json_frames[0][f], json_frames[r][f]) << "run " << r << ", frame " << f;
    }
  }
}

TEST(LocalizeCli, AbsurdOptionsAreRefusedBeforeAnyWork) {
  ::vmap::testing::ScopedTempDir tmp;
  ::vmap::testing::SyntheticOptions synthetic;
  synthetic.num_frames = 6;
  ::vmap::testing::WriteImageFolder(::vmap::testing::RenderSyntheticSequence(synthetic), tmp.path() / "in");
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -q -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  const std::string localize = "localize " + Quote(tmp.path() / "m") + " " + Quote(tmp.path() / "in") + " ";
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {localize + "--threads 40000", "--threads must be 0 to 256"},
      {localize + "--acceptance counts --min-verified 3", "--min-verified 3 must be 8"},
      {localize + "--acceptance counts --min-similarity nan", "--min-similarity nan is outside [0, 1]"},
      {localize + "--candidates 0", "--candidates 0 must be 1 to 10000"},
      {localize + "--max-lost -1", "--max-lost -1 must be 0 to 1000000"},
      {localize + "--lookahead 3", "lookahead 3 is not 1 or 2"},
      {localize + "--ranking bow", "unknown ranking 'bow'"},
      {localize + "--acceptance bow", "unknown acceptance rule 'bow'"},
      {localize + "--max-log10-nfa nan", "--max-log10-nfa nan is outside"},
      {localize + "--min-verified 30", "--min-verified belongs to --acceptance counts (the earlier rule)"},
      {localize + "--acceptance counts --min-link-share 0.5", "--min-link-share belongs to --acceptance chance"},
      {localize + "--recheck-link-share -1", "--recheck-link-share -1 is outside [0, 10]"},
      {localize + "--continuity-share 2", "--continuity-share 2 is outside [0, 1]"},
      {localize + "--window-width 0", "--window-width 0 is outside (0, 1]"},
      {localize + "--window-max-log10-nfa nan", "--window-max-log10-nfa nan is outside"},
      {localize + "--step-back-max-log10-nfa nan", "--step-back-max-log10-nfa nan is outside"},
      {localize + "--to 99", "key image 99 does not exist"},
      {localize + "--start-key 99", "start key image 99 (--start-key) does not exist"},
      {localize + "--start-key -2", "--start-key -2 is not -1"},
      {"localize " + Quote(tmp.path() / "m") + " " + Quote(tmp.path() / "missing.mp4"), "does not exist"},
      {"route " + Quote(tmp.path() / "m") + " --min-backward-verified 2", "--min-backward-verified 2 must be 8"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_EQ(out.find("vmap: error: "), 0u) << c.arguments << "\n" << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
    EXPECT_FALSE(fs::exists(tmp.path() / "m" / kLocalizationCacheFileName)) << "work was done: " << c.arguments;
  }
}

// The bracket test on a subset: a map of the even frames, and each odd frame localized at one of the two key
// images around it (docs/measurements/localization.md has the full sequences).
struct PoseErrors {
  std::vector<double> rotation_deg, translation_deg;  // of each frame's pose to its target key image
};

double BracketShare(const std::string& sequence, int last, PoseErrors* pose_errors = nullptr) {
  ::vmap::testing::ScopedTempDir tmp;
  const auto matcher = CreateOrbMatcher({});
  MapBuilderOptions build;
  build.show_progress = false;
  FrameSourceOptions even;
  even.stride = 2;
  even.last = last;
  {
    const auto source = OpenFrameSource((Shared() / sequence).string(), even);
    ::vmap::testing::BuildMapDirectory(*source, *matcher, build, tmp.path() / "map");
  }
  const LocalizationMap opened = OpenLocalizationMap(tmp.path() / "map", {});
  Localizer localizer(opened.map, opened.keys, *opened.matcher, MapLocalizerOptions(opened));
  FrameSourceOptions odd = even;
  odd.first = 1;
  const auto source = OpenFrameSource((Shared() / sequence).string(), odd);
  LocalizeSequenceOptions run;
  run.show_progress = false;
  long bracketed = 0;
  const std::optional<GroundTruth> truth =
      pose_errors ? FindGroundTruth((Shared() / sequence).string(), SourceFormat::kAuto) : std::nullopt;
  if (pose_errors) {
    EXPECT_TRUE(truth.has_value()) << sequence << " comes with ground truth";
  }
  const LocalizationSummary summary =
      LocalizeSequence(*source, *opened.matcher, localizer, run, [&](const Frame& frame, const LocalizationResult& r) {
        const auto [before, after] = KeysAround(opened.map, frame.source_index);
        bracketed += r.key >= 0 && (r.key == before || r.key == after);
        const RelativePose& pose = r.next_key >= 0 ? r.to_next.pose : r.to_key.pose;
        if (!truth || !pose.valid) return;
        const int target_source = opened.map.key_images[r.next_key >= 0 ? r.next_key : r.key].source_index;
        cv::Matx33d R;
        cv::Vec3d t;
        RelativeFromCameraToWorld(truth->camera_to_world.at(frame.source_index),
                                  truth->camera_to_world.at(target_source), &R, &t);
        const cv::Matx33d dR = pose.R * R.t();
        pose_errors->rotation_deg.push_back(std::acos(std::clamp((cv::trace(dR) - 1.0) / 2.0, -1.0, 1.0)) * 180 / M_PI);
        pose_errors->translation_deg.push_back(std::acos(std::clamp(pose.t.dot(t) / cv::norm(t), -1.0, 1.0)) * 180 /
                                               M_PI);
      });
  EXPECT_EQ(summary.frames, (last + 1) / 2);
  return static_cast<double>(bracketed) / summary.frames;
}

TEST(LocalizationTruth, OddFramesOfKitti07AreBetweenTheirKeyImages) {
  SKIP_WITHOUT_SHARED();
  PoseErrors errors;
  EXPECT_GE(BracketShare("data/kitti07", 99, &errors), 0.95);
  // With KITTI's camera each frame also gets the pose of the key image ahead: against the ground truth.
  ASSERT_GE(errors.rotation_deg.size(), 40u);
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  EXPECT_LT(median(errors.rotation_deg), 0.5);
  EXPECT_LT(median(errors.translation_deg), 5.0);
}

TEST(LocalizationTruth, OddFramesOfRedkitchenAreBetweenTheirKeyImages) {
  SKIP_WITHOUT_SHARED();
  EXPECT_GE(BracketShare("data/redkitchen", 199), 0.95);
}

}  // namespace
}  // namespace vmap
