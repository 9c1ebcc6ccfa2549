#include "vmap/report/html_report.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/report/report_assets.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/report_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using report_test::ReadText;
using testing::ScopedTempDir;

// Every path below `root`, relative, as a sorted set: what a directory looks like.
std::set<std::string> Listing(const fs::path& root) {
  std::set<std::string> paths;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    paths.insert(entry.path().lexically_relative(root).generic_string());
  }
  return paths;
}

TEST(MapReportTest, WritesOnePageWithAFigurePerLinkAndAThumbnailPerKeyImage) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  const VisualMap map = report_test::WriteSyntheticMap(dir);
  ASSERT_EQ(map.key_images.size(), 6u);
  WriteMapReport(dir);

  const std::string html = ReadText(dir / kReportFileName);
  EXPECT_EQ(report_test::CountOccurrences(html, "<figure class=\"match-figure"), static_cast<int>(map.links.size()));
  EXPECT_EQ(report_test::CountOccurrences(html, "<figure class=\"match-figure below-tau\""), 1);
  EXPECT_EQ(report_test::CountOccurrences(html, "<figure id=\"key-"), static_cast<int>(map.key_images.size()));
  EXPECT_EQ(report_test::CountOccurrences(html, "<svg class=\"plot\""), 2);
  // Offline: no address on the network anywhere, and a policy that refuses any request.
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_NE(html.find("Content-Security-Policy\" content=\"default-src 'none'"), std::string::npos);
  // The summary names the matcher, the verifier and tau from the options.
  EXPECT_NE(html.find("<td>orb (features 2000)</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>magsac (threshold 0.5)</td>"), std::string::npos);
  EXPECT_NE(html.find("Key images m</th><td>6 (15.0 % of the frames)"), std::string::npos);

  // Every image the page references exists inside the map directory and is a sensibly sized JPEG.
  std::vector<std::string> sources = report_test::AttributeValues(html, "src");
  // The route preview: a video of the key images in order, one frame each.
  const auto video = std::find(sources.begin(), sources.end(), "report/route.mp4");
  ASSERT_NE(video, sources.end());
  cv::VideoCapture capture((dir / *video).string());
  ASSERT_TRUE(capture.isOpened());
  EXPECT_EQ(static_cast<size_t>(capture.get(cv::CAP_PROP_FRAME_COUNT)), map.key_images.size());
  sources.erase(video);
  ASSERT_EQ(sources.size(), map.key_images.size() + map.links.size() + 1);  // + the step-through player
  for (const std::string& src : sources) {
    EXPECT_EQ(src.find(".."), std::string::npos) << src;
    EXPECT_EQ(src.rfind("report/", 0), 0u) << src;
    const cv::Mat image = cv::imread((dir / src).string());
    ASSERT_FALSE(image.empty()) << src;
    EXPECT_LE(image.cols, 960) << src;
  }
  EXPECT_EQ(cv::imread((dir / "report/keys/000000.jpg").string()).cols, 320);
  // Lazy loading keeps a long map quick to open.
  EXPECT_EQ(report_test::CountOccurrences(html, "loading=\"lazy\""),
            static_cast<int>(map.key_images.size() + map.links.size()));
}

TEST(MapReportTest, SimilarityPlotShowsEveryEvaluationTauAndTheLinks) {
  ScopedTempDir temp;
  const VisualMap map = report_test::WriteSyntheticMap(temp.path());
  WriteMapReport(temp.path());
  const std::string svg = report_test::SvgById(ReadText(temp.path() / kReportFileName), "similarity-plot");
  ASSERT_FALSE(svg.empty());
  const report_test::PlotAxes axes = report_test::ParsePlotAxes(svg);
  const double x_tolerance = 0.02 * (axes.x_max - axes.x_min) / (axes.right - axes.left) * 2;
  const double y_tolerance = 0.02;

  size_t compared = 0;
  for (const KeyImage& key : map.key_images) {
    std::vector<Evaluation> expected;
    for (const Evaluation& e : map.evaluations) {
      if (e.key_frame == key.frame_index) expected.push_back(e);
    }
    const auto points =
        report_test::PolylinePoints(svg, "data-key-frame=\"" + std::to_string(key.frame_index) + "\"", axes);
    ASSERT_EQ(points.size(), expected.size()) << "key frame " << key.frame_index;
    for (size_t i = 0; i < points.size(); ++i) {
      EXPECT_NEAR(points[i].x, expected[i].frame, x_tolerance);
      EXPECT_NEAR(points[i].y, expected[i].similarity, y_tolerance);
      ++compared;
    }
  }
  EXPECT_EQ(compared, map.evaluations.size());

  for (size_t i = 0; i < map.links.size(); ++i) {
    const auto centre = report_test::CircleCentres(svg, "data-link=\"" + std::to_string(i) + "\"", axes);
    ASSERT_EQ(centre.size(), 1u);
    EXPECT_NEAR(centre[0].x, map.key_images[map.links[i].to_key].frame_index, x_tolerance);
    EXPECT_NEAR(centre[0].y, map.links[i].similarity, y_tolerance);
  }
  // tau is a dashed rule at its value; the failed comparison is a cross.
  const size_t tau_at = svg.find("data-tau=\"0.35\"");
  ASSERT_NE(tau_at, std::string::npos);
  const std::string tau_tag = svg.substr(tau_at, svg.find('>', tau_at) - tau_at);
  EXPECT_NEAR(axes.ToData({0, std::stod(report_test::AttributeValues(tau_tag, "y1").at(0))}).y, 0.35, y_tolerance);
  EXPECT_EQ(report_test::CountOccurrences(svg, "class=\"series failed\""), 1);
  const std::string keys_group = svg.substr(svg.find("class=\"series key-images\""));
  EXPECT_EQ(report_test::CountOccurrences(keys_group.substr(0, keys_group.find("</g>")), "<line"),
            static_cast<int>(map.key_images.size()));
}

TEST(MapReportTest, MapWithOneKeyImageAndNoLinksStillGetsAPage) {
  ScopedTempDir temp;
  report_test::SyntheticMapOptions options;
  options.num_frames = 1;
  options.below_tau_links.clear();
  const VisualMap map = report_test::WriteSyntheticMap(temp.path(), options);
  ASSERT_EQ(map.key_images.size(), 1u);
  ASSERT_TRUE(map.links.empty());
  WriteMapReport(temp.path());
  const std::string html = ReadText(temp.path() / kReportFileName);
  EXPECT_EQ(report_test::CountOccurrences(html, "<figure class=\"match-figure"), 0);
  EXPECT_EQ(report_test::CountOccurrences(html, "<figure id=\"key-"), 1);
  EXPECT_NE(html.find("there are no links"), std::string::npos);
  EXPECT_EQ(html.find("<video"), std::string::npos);  // one image is no route
  EXPECT_NE(html.find("</html>"), std::string::npos);
}

TEST(MapReportTest, RewritingReplacesTheReportAndLeavesNoTemporaryFiles) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  report_test::WriteSyntheticMap(dir);
  WriteMapReport(dir);
  const std::set<std::string> first = Listing(temp.path());
  WriteMapReport(dir);
  EXPECT_EQ(Listing(temp.path()), first);
  for (const std::string& path : first) {
    EXPECT_TRUE(path.rfind("map", 0) == 0) << path;  // nothing beside the map directory
    EXPECT_EQ(path.find("/."), std::string::npos) << "temporary left behind: " << path;
  }
}

TEST(MapReportTest, RewritingKeepsWhatAUserPutInReportBesidesItsOwnFiles) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  report_test::WriteSyntheticMap(dir);
  WriteMapReport(dir);
  std::ofstream(dir / "report/notes.txt") << "the lighting changed at key 3";
  std::ofstream(dir / "report/keys/stale.jpg") << "not the report's any more";
  WriteMapReport(dir);
  EXPECT_EQ(ReadText(dir / "report/notes.txt"), "the lighting changed at key 3");
  EXPECT_FALSE(fs::exists(dir / "report/keys/stale.jpg"));  // keys/ is the report's own: replaced whole
  EXPECT_TRUE(fs::exists(dir / "report/keys/000000.jpg"));
}

TEST(MapReportTest, MissingOrMalformedMapsGiveClearErrorsAndWriteNothing) {
  ScopedTempDir temp;
  const fs::path missing = temp.path() / "no_such_map";
  EXPECT_NE(testing::InputErrorMessage([&] { WriteMapReport(missing); }).find("no_such_map"), std::string::npos);
  EXPECT_FALSE(fs::exists(missing));

  const fs::path empty = temp.path() / "empty";
  fs::create_directories(empty);
  EXPECT_NE(testing::InputErrorMessage([&] { WriteMapReport(empty); }).find("map.json"), std::string::npos);
  EXPECT_TRUE(fs::is_empty(empty));

  const fs::path incomplete = temp.path() / "incomplete";
  report_test::WriteSyntheticMap(incomplete);
  fs::remove(incomplete / "keys/000018.png");
  const std::set<std::string> before = Listing(incomplete);
  EXPECT_NE(testing::InputErrorMessage([&] { WriteMapReport(incomplete); }).find("000018.png"), std::string::npos);
  EXPECT_EQ(Listing(incomplete), before);

  const fs::path garbled = temp.path() / "garbled";
  report_test::WriteSyntheticMap(garbled);
  std::ofstream(garbled / "map.json") << "{ not json";
  EXPECT_NE(testing::InputErrorMessage([&] { WriteMapReport(garbled); }).find("not valid JSON"), std::string::npos);
  EXPECT_FALSE(fs::exists(garbled / kReportFileName));
}

TEST(MapReportTest, BadOptionsNameTheFieldAndWriteNothing) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  report_test::WriteSyntheticMap(dir);
  const std::set<std::string> before = Listing(dir);
  const std::vector<std::pair<std::string, std::function<void(MapReportOptions&)>>> cases = {
      {"thumbnail_width 31 px is outside [32, 4096]", [](MapReportOptions& o) { o.thumbnail_width = 31; }},
      {"figure_width 8193 px is outside [64, 8192]", [](MapReportOptions& o) { o.figure_width = 8193; }},
      {"jpeg_quality 0 is outside [1, 100]", [](MapReportOptions& o) { o.jpeg_quality = 0; }},
      {"route_fps 0 is outside (0, 120]", [](MapReportOptions& o) { o.route_fps = 0.0; }},
      {"route_fps nan is outside (0, 120]", [](MapReportOptions& o) { o.route_fps = std::nan(""); }},
  };
  EXPECT_NO_THROW(MapReportOptions{}.Check());
  for (const auto& [message, spoil] : cases) {
    MapReportOptions options;
    spoil(options);
    EXPECT_EQ(testing::InputErrorMessage([&] { WriteMapReport(dir, options); }).rfind(message, 0), 0u) << message;
  }
  EXPECT_EQ(Listing(dir), before);
}

// The style sheet and the script are the files in report/assets, embedded at build time, carried inline.
TEST(MapReportTest, PageCarriesTheEmbeddedStyleAndScript) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  report_test::WriteSyntheticMap(dir);
  WriteMapReport(dir);
  const std::string html = ReadText(dir / kReportFileName);
  const std::string css(report::ReportCss()), js(report::ReportJs());
  EXPECT_NE(css.find(".match-figure.below-tau {"), std::string::npos);
  EXPECT_NE(js.find("vmap-selfcheck"), std::string::npos);
  EXPECT_EQ(report_test::CountOccurrences(html, "<style>\n" + css + "</style>"), 1);
  EXPECT_EQ(report_test::CountOccurrences(html, "<script>\n" + js + "</script>"), 1);
}

// Rewrites one key image's path in map.json.
void SetKeyImagePath(const fs::path& dir, int key, const std::string& image) {
  nlohmann::json doc = nlohmann::json::parse(ReadText(dir / "map.json"));
  doc["key_images"][key]["image"] = image;
  std::ofstream(dir / "map.json") << doc.dump();
}

TEST(MapReportTest, KeyImagePathsCannotLeaveTheMapDirectory) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  const VisualMap map = report_test::WriteSyntheticMap(dir);
  const fs::path outside = temp.path() / "secret.png";
  cv::imwrite(outside.string(), cv::Mat(8, 8, CV_8UC3, cv::Scalar::all(9)));

  SetKeyImagePath(dir, 1, "../secret.png");
  EXPECT_NE(testing::InputErrorMessage([&] { WriteMapReport(dir); }).find("outside the map directory"),
            std::string::npos);
  SetKeyImagePath(dir, 1, outside.string());
  EXPECT_NE(testing::InputErrorMessage([&] { WriteMapReport(dir); }).find("outside the map directory"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / kReportFileName));
  EXPECT_FALSE(fs::exists(dir / kReportAssetsDirectory));

  // A symbolic link inside the map that leads out is refused too.
  fs::create_symlink(outside, dir / "keys/link.png");
  SetKeyImagePath(dir, 1, "keys/link.png");
  EXPECT_NE(testing::InputErrorMessage([&] { WriteMapReport(dir); }).find("resolves outside"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / kReportFileName));

  KeyImage escaping = map.key_images[0];
  escaping.image_file = "keys/../../secret.png";
  EXPECT_THROW(KeyImageFile(dir, escaping), InputError);
}

TEST(MapReportTest, DrawMapLinkNamesAMissingLink) {
  ScopedTempDir temp;
  const VisualMap map = report_test::WriteSyntheticMap(temp.path());
  const cv::Mat figure = DrawMapLink(temp.path(), map, 0);
  EXPECT_EQ(figure.cols, 2 * 320 + 4);
  const std::string error = testing::InputErrorMessage([&] { DrawMapLink(temp.path(), map, 17); });
  EXPECT_NE(error.find("link 17 does not exist"), std::string::npos) << error;
  EXPECT_NE(error.find("0 to 4"), std::string::npos) << error;
}

SweepResult SyntheticSweep(const fs::path& maps) {
  SweepResult sweep;
  sweep.input.path = "synthetic/slide";
  sweep.num_frames = 100;
  sweep.options_json = R"({"matcher":{"name":"orb"},"verifier":{"method":"magsac"}})";
  const double taus[] = {0.2, 0.4, 0.6, 0.8};
  const int keys[] = {5, 9, 20, 41};
  const double quality[] = {0.61, 0.7, 0.66, 0.5};
  for (int i = 0; i < 4; ++i) {
    SweepRow row;
    row.tau = taus[i];
    row.num_key_images = keys[i];
    row.key_image_percent = keys[i];
    row.min_verified = 10 * i;
    row.max_verified = 100 + i;
    row.mean_verified = 50.5 + i;
    row.mean_similarity = 0.3 + 0.1 * i;
    row.quality = quality[i];
    sweep.rows.push_back(row);
  }
  sweep.best_row = 1;
  fs::create_directories(maps / "tau_0.40");
  fs::create_directories(maps / "tau_0.60");
  std::ofstream(maps / "tau_0.60" / kReportFileName) << "x";
  sweep.rows[1].map_directory = (maps / "tau_0.40").string();  // absolute
  sweep.rows[2].map_directory = "tau_0.60";                    // relative to the report
  return sweep;
}

TEST(SweepReportTest, TableMarksTheBestTauAndLinksTheMapsRelatively) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "sweep";
  const SweepResult sweep = SyntheticSweep(dir);
  fs::create_directories(dir);
  WriteSweepReport(sweep, dir);
  const std::string html = ReadText(dir / kReportFileName);
  EXPECT_EQ(report_test::CountOccurrences(html, "<tr class=\""), 4);
  EXPECT_NE(html.find("<tr class=\"best\" data-tau=\"0.4\">"), std::string::npos);
  EXPECT_EQ(report_test::CountOccurrences(html, "class=\"best\""), 1);
  const std::vector<std::string> links = report_test::AttributeValues(html, "href");
  std::vector<std::string> map_links;
  for (const std::string& href : links) {
    if (href[0] != '#') map_links.push_back(href);
  }
  EXPECT_EQ(map_links, (std::vector<std::string>{"tau_0.40/map.json", "tau_0.60/report.html"}));
  EXPECT_EQ(html.find("http:"), std::string::npos);
  EXPECT_EQ(html.find("https:"), std::string::npos);
}

TEST(SweepReportTest, PlotsShowKeyImagesAndQualityAgainstTau) {
  ScopedTempDir temp;
  const SweepResult sweep = SyntheticSweep(temp.path());
  WriteSweepReport(sweep, temp.path());
  const std::string html = ReadText(temp.path() / kReportFileName);
  const std::string keys_svg = report_test::SvgById(html, "keys-plot");
  const std::string quality_svg = report_test::SvgById(html, "quality-plot");
  const report_test::PlotAxes keys_axes = report_test::ParsePlotAxes(keys_svg);
  const report_test::PlotAxes quality_axes = report_test::ParsePlotAxes(quality_svg);
  const auto m = report_test::PolylinePoints(keys_svg, "points=", keys_axes);
  ASSERT_EQ(m.size(), sweep.rows.size());
  std::vector<cv::Point2d> q;
  const std::string quality_group = quality_svg.substr(quality_svg.find("class=\"series quality\""));
  q = report_test::PolylinePoints(quality_group.substr(0, quality_group.find("</g>")), "points=", quality_axes);
  ASSERT_EQ(q.size(), sweep.rows.size());
  for (size_t i = 0; i < sweep.rows.size(); ++i) {
    EXPECT_NEAR(m[i].x, sweep.rows[i].tau, 0.005);
    EXPECT_NEAR(m[i].y, sweep.rows[i].num_key_images, 0.2);
    EXPECT_NEAR(q[i].x, sweep.rows[i].tau, 0.005);
    EXPECT_NEAR(q[i].y, sweep.rows[i].quality, 0.005);
  }
  const std::string best_group = quality_svg.substr(quality_svg.find("class=\"series best\""));
  const auto best = report_test::CircleCentres(best_group.substr(0, best_group.find("</g>")), "cx=", quality_axes);
  ASSERT_EQ(best.size(), 1u);
  EXPECT_NEAR(best[0].y, 0.7, 0.005);
}

// Thresholds given out of order (--thresholds 0.6,0.2,0.8,0.4): the lines were drawn in that order, a zigzag.
TEST(SweepReportTest, PlotsDrawTheThresholdsInOrderOfTau) {
  ScopedTempDir temp;
  SweepResult sweep = SyntheticSweep(temp.path());
  sweep.rows = {sweep.rows[2], sweep.rows[0], sweep.rows[3], sweep.rows[1]};
  sweep.best_row = 3;
  WriteSweepReport(sweep, temp.path());
  const std::string html = ReadText(temp.path() / kReportFileName);
  const std::string keys_svg = report_test::SvgById(html, "keys-plot");
  const std::string quality_svg = report_test::SvgById(html, "quality-plot");
  const auto m = report_test::PolylinePoints(keys_svg, "points=", report_test::ParsePlotAxes(keys_svg));
  const std::string quality_group = quality_svg.substr(quality_svg.find("class=\"series quality\""));
  const auto q = report_test::PolylinePoints(quality_group.substr(0, quality_group.find("</g>")),
                                             "points=", report_test::ParsePlotAxes(quality_svg));
  ASSERT_EQ(m.size(), 4u);
  ASSERT_EQ(q.size(), 4u);
  const double taus[] = {0.2, 0.4, 0.6, 0.8};
  const int keys[] = {5, 9, 20, 41};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(m[i].x, taus[i], 0.005) << i;
    EXPECT_NEAR(m[i].y, keys[i], 0.2) << i;
    EXPECT_NEAR(q[i].x, taus[i], 0.005) << i;
  }
}

}  // namespace
}  // namespace vmap
