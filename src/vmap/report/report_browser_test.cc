// Renders the reports in Debian's headless Chromium: the page must load offline with no console message,
// every image must decode, the figure count must match the links, and the screenshot must not be blank.

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/map/map_io.h"
#include "vmap/report/html_report.h"
#include "vmap/report/localization_report.h"
#include "vmap/testing/report_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using report_test::ReadText;
using testing::ScopedTempDir;

constexpr const char* kChromium = "/usr/bin/chromium";

// Chromium takes most of a small machine: test processes running in parallel (ctest -j) take turns.
class ChromiumTurn {
 public:
  ChromiumTurn() : fd_(open((fs::temp_directory_path() / "vmap-chromium-tests.lock").c_str(), O_CREAT | O_RDWR, 0666)) {
    if (fd_ >= 0) flock(fd_, LOCK_EX);
  }
  ~ChromiumTurn() {
    if (fd_ >= 0) flock(fd_, LOCK_UN), close(fd_);
  }

 private:
  int fd_;
};

struct ChromiumResult {
  int status = -1;
  std::string dom;
  std::string log;
};

// One headless run with a fresh profile; `action` is e.g. "--dump-dom" or "--screenshot=FILE".
ChromiumResult RunChromium(const std::string& action, const std::string& url, const fs::path& work) {
  const fs::path profile = work / ("profile-" + std::to_string(rand()));
  const fs::path out = work / "chromium.out", err = work / "chromium.err";
  const std::string command = std::string("timeout 120 ") + kChromium +
                              " --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking"
                              " --disable-component-update --disable-sync --disable-extensions --hide-scrollbars"
                              " --enable-logging=stderr --v=0 --virtual-time-budget=15000 --window-size=1280,2000" +
                              " --user-data-dir=" + testing::Quote(profile.string()) + " " + action + " " +
                              testing::Quote(url) + " > " + testing::Quote(out.string()) + " 2> " +
                              testing::Quote(err.string());
  ChromiumResult result;
  {
    ChromiumTurn turn;
    result.status = std::system(command.c_str());
  }
  result.dom = ReadText(out);
  result.log = ReadText(err);
  std::error_code ignored;
  fs::remove_all(profile, ignored);
  return result;
}

std::string FileUrl(const fs::path& file) { return "file://" + fs::absolute(file).lexically_normal().string(); }

// Console lines Chromium logs for the page (errors, CSP violations, failed loads, anything printed).
std::vector<std::string> ConsoleLines(const std::string& log) {
  std::vector<std::string> lines;
  size_t begin = 0;
  while (begin < log.size()) {
    size_t end = log.find('\n', begin);
    if (end == std::string::npos) end = log.size();
    const std::string line = log.substr(begin, end - begin);
    if (line.find(":CONSOLE") != std::string::npos || line.find("Content Security Policy") != std::string::npos ||
        line.find("net::ERR") != std::string::npos) {
      lines.push_back(line);
    }
    begin = end + 1;
  }
  return lines;
}

// Loads report.html#selfcheck: the page loads every image and writes what it found into the DOM.
nlohmann::json SelfCheck(const fs::path& report, const fs::path& work) {
  const ChromiumResult run = RunChromium("--dump-dom", FileUrl(report) + "#selfcheck", work);
  EXPECT_EQ(run.status, 0) << run.log;
  EXPECT_EQ(ConsoleLines(run.log), std::vector<std::string>{}) << "the page logged to the console";
  const std::string marker = "<pre id=\"vmap-selfcheck\">";
  const size_t at = run.dom.find(marker);
  if (at == std::string::npos) {
    ADD_FAILURE() << "the self-check did not finish; the page's script did not run\n" << run.log;
    return nlohmann::json::object();
  }
  const size_t begin = at + marker.size();
  std::string text = run.dom.substr(begin, run.dom.find("</pre>", begin) - begin);
  for (auto [entity, c] : {std::pair{"&quot;", "\""}, {"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}}) {
    for (size_t p = text.find(entity); p != std::string::npos; p = text.find(entity, p + 1)) {
      text.replace(p, std::string(entity).size(), c);
    }
  }
  return nlohmann::json::parse(text);
}

// The page as a 1280 x 2000 screenshot: something must be drawn (not a blank or single-colour page).
void ExpectScreenshotNotBlank(const fs::path& report, const fs::path& work) {
  const fs::path shot = work / "screenshot.png";
  const ChromiumResult run = RunChromium("--screenshot=" + testing::Quote(shot.string()), FileUrl(report), work);
  ASSERT_EQ(run.status, 0) << run.log;
  const cv::Mat image = cv::imread(shot.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty()) << "no screenshot written\n" << run.log;
  EXPECT_EQ(image.cols, 1280);
  EXPECT_EQ(image.rows, 2000);
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  EXPECT_GT(stddev[0], 20.0) << "the screenshot is nearly uniform";
  // The header band is dark and the body light: the styles were applied.
  EXPECT_LT(cv::mean(image(cv::Rect(0, 0, 1280, 40)))[0], 90.0);
  EXPECT_GT(mean[0], 120.0);
}

class ReportBrowserTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kChromium)) {
      GTEST_SKIP() << kChromium << " is missing: install Debian's chromium (scripts/install-deps.sh --with-browser)";
    }
  }
};

TEST_F(ReportBrowserTest, MapReportLoadsOfflineWithEveryImageAndFigure) {
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  report_test::SyntheticMapOptions options;
  options.num_frames = 200;  // 23 key images: most images are far below the first screen (lazy)
  const VisualMap map = report_test::WriteSyntheticMap(dir, options);
  WriteMapReport(dir);

  const nlohmann::json check = SelfCheck(dir / kReportFileName, temp.path());
  ASSERT_TRUE(check.contains("images"));
  EXPECT_EQ(check["broken"], nlohmann::json::array());
  EXPECT_EQ(check["images"].get<size_t>(), map.key_images.size() + map.links.size() + 1);
  EXPECT_EQ(check["match_figures"].get<size_t>(), map.links.size());
  EXPECT_EQ(check["key_images"].get<size_t>(), map.key_images.size());
  EXPECT_EQ(check["plots"].get<int>(), 2);
  EXPECT_EQ(check["videos"].get<int>(), 1);
  EXPECT_EQ(check["broken_videos"], nlohmann::json::array());
  ExpectScreenshotNotBlank(dir / kReportFileName, temp.path());
}

TEST_F(ReportBrowserTest, ARequestToTheNetworkWouldBeCaught) {
  // The console check must be able to fail: a page that reaches for a CDN is refused and logged.
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  report_test::WriteSyntheticMap(dir);
  WriteMapReport(dir);
  std::string html = ReadText(dir / kReportFileName);
  html.replace(html.find("</main>"), 0, "<img src=\"https://cdn.example.com/logo.png\">");
  std::ofstream(dir / kReportFileName) << html;
  const ChromiumResult run = RunChromium("--dump-dom", FileUrl(dir / kReportFileName), temp.path());
  const std::vector<std::string> lines = ConsoleLines(run.log);
  ASSERT_EQ(lines.size(), 1u) << run.log;
  EXPECT_NE(lines[0].find("cdn.example.com"), std::string::npos);
}

TEST_F(ReportBrowserTest, BrokenImageIsDetected) {
  // The self-check itself must be able to fail: remove one figure and it has to be reported.
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  report_test::WriteSyntheticMap(dir);
  WriteMapReport(dir);
  fs::remove(dir / "report/links/000003.jpg");
  const nlohmann::json check = SelfCheck(dir / kReportFileName, temp.path());
  EXPECT_EQ(check["broken"], nlohmann::json::array({"report/links/000003.jpg"}));
}

TEST_F(ReportBrowserTest, SweepReportLoadsOffline) {
  ScopedTempDir temp;
  SweepResult sweep;
  sweep.input.path = "synthetic";
  sweep.num_frames = 50;
  for (int i = 1; i <= 5; ++i) {
    SweepRow row;
    row.tau = 0.15 * i;
    row.num_key_images = 3 * i * i;
    row.key_image_percent = 100.0 * row.num_key_images / 50;
    row.mean_similarity = 0.1 * i;
    row.quality = 0.5 * (1 - row.num_key_images / 50.0 + row.mean_similarity);
    sweep.rows.push_back(row);
  }
  sweep.best_row = 2;
  report_test::WriteSyntheticMap(temp.path() / "tau_0.45");
  WriteMapReport(temp.path() / "tau_0.45");
  sweep.rows[2].map_directory = (temp.path() / "tau_0.45").string();
  WriteSweepReport(sweep, temp.path());

  const nlohmann::json check = SelfCheck(temp.path() / kReportFileName, temp.path());
  EXPECT_EQ(check["plots"].get<int>(), 2);
  EXPECT_EQ(check["images"].get<int>(), 0);
  ExpectScreenshotNotBlank(temp.path() / kReportFileName, temp.path());
}

TEST_F(ReportBrowserTest, ReportOfARealMapBuiltFromSharedData) {
  const fs::path images = fs::path(testing::SharedDir()) / "data/rccar_room/images";
  if (!fs::exists(testing::VmapBinary()) || testing::SharedDir().empty() || !fs::exists(images)) {
    GTEST_SKIP() << "needs the vmap binary and " << images;
  }
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "rccar_map";
  const std::string command = testing::Quote(testing::VmapBinary()) + " build " + testing::Quote(images.string()) +
                              " -o " + testing::Quote(dir.string()) + " --stride 3 --last 119 --report -q > " +
                              testing::Quote((temp.path() / "build.log").string()) + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << ReadText(temp.path() / "build.log");
  const VisualMap map = ReadMap(dir);
  ASSERT_GE(map.key_images.size(), 2u);
  const nlohmann::json check = SelfCheck(dir / kReportFileName, temp.path());
  EXPECT_EQ(check["broken"], nlohmann::json::array());
  EXPECT_EQ(check["match_figures"].get<size_t>(), map.links.size());
  EXPECT_EQ(check["key_images"].get<size_t>(), map.key_images.size());
  ExpectScreenshotNotBlank(dir / kReportFileName, temp.path());
}

TEST_F(ReportBrowserTest, LocalizationReportLoadsOffline) {
  // A run whose query frames are the map's own key images (an image folder), localized one by one.
  ScopedTempDir temp;
  const fs::path dir = temp.path() / "map";
  const VisualMap map = report_test::WriteSyntheticMap(dir);
  LocalizationRun run;
  run.info.map_directory = dir.string();
  run.info.query = (dir / "keys").string();
  run.info.query_format = SourceFormat::kImageFolder;
  for (int i = 0; i < static_cast<int>(map.key_images.size()); ++i) {
    LocalizationResult r;
    r.frame_index = r.source_index = i;
    r.status = i == 0   ? LocalizationStatus::kRelocalized
               : i == 2 ? LocalizationStatus::kLost
                        : LocalizationStatus::kTracking;
    r.key = i == 2 ? 1 : i;
    r.next_key = r.key + 1 < static_cast<int>(map.key_images.size()) ? r.key + 1 : -1;
    r.to_key.similarity = 0.8;
    r.to_next.similarity = 0.4;
    run.frames.push_back(r);
    ++run.summary.frames;
  }
  const fs::path out = temp.path() / "run_report";
  LocalizationReportOptions options;
  options.pairs = 3;
  WriteLocalizationReport(run, map, dir, out, options);
  const nlohmann::json check = SelfCheck(out / kReportFileName, temp.path());
  ASSERT_TRUE(check.contains("images"));
  EXPECT_EQ(check["broken"], nlohmann::json::array());
  EXPECT_EQ(check["images"].get<int>(), 3);
  EXPECT_EQ(check["match_figures"].get<int>(), 3);
  EXPECT_EQ(check["plots"].get<int>(), 2);
  ExpectScreenshotNotBlank(out / kReportFileName, temp.path());
}

}  // namespace
}  // namespace vmap
