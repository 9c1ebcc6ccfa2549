// `vmap match`'s heading: printed, in the JSON, in degrees with --camera, and its options' errors.

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::Quote;
using testing::RunVmap;

namespace {

// A michigan image and a copy of it shifted `shift` px to the right, in another light: x in the copy minus
// x in the original is `shift` by construction.
void WriteShiftedPair(const fs::path& directory, double shift) {
  const cv::Mat image =
      cv::imread(testing::SharedDir() + "/data/michigan_seasons/images/0103.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty());
  cv::Mat shifted;
  cv::warpAffine(image, shifted, cv::Matx23d(1, 0, shift, 0, 1, 0), image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  shifted.convertTo(shifted, CV_8U, 0.7, 20.0);
  cv::imwrite((directory / "a.png").string(), image);
  cv::imwrite((directory / "b.png").string(), shifted);
}

TEST(MatchCli, ReportsTheHeadingInPixelsAndWithACameraInDegrees) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  const double shift = 37.0;
  WriteShiftedPair(tmp.path(), shift);
  const std::string pair = "match " + Quote(tmp.path() / "a.png") + " " + Quote(tmp.path() / "b.png");
  std::string out;
  ASSERT_EQ(RunVmap(pair + " --json " + Quote(tmp.path() / "m.json"), &out), 0) << out;
  EXPECT_NE(out.find("heading     "), std::string::npos) << out;
  auto json = nlohmann::json::parse(std::ifstream(tmp.path() / "m.json"));
  ASSERT_TRUE(json["heading_px"].is_number()) << json.dump();
  // ORB scores no match: null, not a 0 that would read as the worst score; nan in --list, as numpy reads it.
  ASSERT_FALSE(json["matches"].empty());
  for (const auto& match : json["matches"]) EXPECT_TRUE(match["score"].is_null()) << match.dump();
  ASSERT_EQ(RunVmap(pair + " --list", &out), 0) << out;
  EXPECT_NE(out.find(" nan 1\n"), std::string::npos) << out;
  EXPECT_NEAR(json["heading_px"].get<double>(), shift, 1.5);
  EXPECT_TRUE(json["heading_deg"].is_null()) << "no camera, no degrees";
  // A pure shift: F holds with many inliers, whose median is the heading.
  EXPECT_EQ(json["heading_method"], "verified_median");
  EXPECT_GT(json["heading_confidence"].get<double>(), 0.5) << "a pure shift: most matches agree";
  EXPECT_LE(json["heading_confidence"].get<double>(), 1.0);

  ASSERT_EQ(RunVmap(pair + " --heading-min-verified 0 --json " + Quote(tmp.path() / "mode.json"), &out), 0) << out;
  const auto mode = nlohmann::json::parse(std::ifstream(tmp.path() / "mode.json"));
  EXPECT_EQ(mode["heading_method"], "displacement_mode");
  EXPECT_NEAR(mode["heading_px"].get<double>(), shift, 1.5);

  // The other way round the scene moves the other way.
  const std::string reversed = "match " + Quote(tmp.path() / "b.png") + " " + Quote(tmp.path() / "a.png");
  const double fx = 800.0;
  ASSERT_EQ(RunVmap(reversed + " --camera 800,800,511.5,191.5 --json " + Quote(tmp.path() / "r.json"), &out), 0) << out;
  EXPECT_NE(out.find(" deg"), std::string::npos) << out;
  json = nlohmann::json::parse(std::ifstream(tmp.path() / "r.json"));
  EXPECT_NEAR(json["heading_px"].get<double>(), -shift, 1.5);
  // A shift of s px is a turn of about atan(s / f) near the image's centre.
  EXPECT_NEAR(json["heading_deg"].get<double>(), -std::atan(shift / fx) * 180.0 / M_PI, 0.3);
  // A camera within the accepted ranges whose distortion (k4 = 999) does not invert at the heading's point: the
  // degrees are unknown, said as such (they printed as "-nan deg"), and null in the JSON.
  ASSERT_EQ(RunVmap(reversed + " --camera 800,800,511.5,191.5,0,0,0,0,0,999,0,0 --json " + Quote(tmp.path() / "k.json"),
                    &out),
            0)
      << out;
  EXPECT_EQ(out.find("nan"), std::string::npos) << out;
  EXPECT_NE(out.find("deg unknown"), std::string::npos) << out;
  EXPECT_TRUE(nlohmann::json::parse(std::ifstream(tmp.path() / "k.json"))["heading_deg"].is_null());
}

// `vmap match` on two key images of a map verifies as the map's link was (docs/match.md): kitti07's grey PNGs decode as
// its frames did, so the counts agree but for links that kept their deciding comparison. With OpenCV's USAC_MAGSAC,
// the estimator of the localizer and of `vmap build --exhaustive`, 8 of 114 links at tau 0.6 agreed.
TEST(MatchCli, TwoKeyImagesVerifyAsTheirLinkInTheMap) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  std::string out;
  ASSERT_EQ(
      RunVmap("build " + Quote(testing::SharedDir() + "/data/kitti07") + " --last 60 --tau 0.6 -q -o " + Quote(map),
              &out),
      0)
      << out;
  std::ifstream map_file(map / "map.json");
  const nlohmann::json map_json = nlohmann::json::parse(map_file);
  const nlohmann::json& keys = map_json["key_images"];
  int same = 0, links = 0;
  for (const nlohmann::json& link : map_json["links"]) {
    const fs::path json = tmp.path() / "link.json";
    ASSERT_EQ(
        RunVmap("match " + Quote(map / keys[link["from"].get<int>()]["image"].get<std::string>()) + " " +
                    Quote(map / keys[link["to"].get<int>()]["image"].get<std::string>()) + " --json " + Quote(json),
                &out),
        0)
        << out;
    std::ifstream in(json);
    const nlohmann::json match = nlohmann::json::parse(in);
    ++links;
    same += match["num_tentative"] == link["tentative"] && match["num_verified"] == link["verified"];
  }
  ASSERT_GE(links, 10);
  EXPECT_GE(same, links * 9 / 10) << same << " of " << links << " links";
}

TEST(MatchCli, HeadingOptionErrorsNameTheirFlags) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  WriteShiftedPair(tmp.path(), 10.0);
  const std::string pair = "match " + Quote(tmp.path() / "a.png") + " " + Quote(tmp.path() / "b.png");
  for (const std::string flag :
       {"--heading-window 0", "--heading-window-dy -1", "--heading-min-votes 0", "--heading-min-verified -1"}) {
    std::string out;
    EXPECT_EQ(RunVmap(pair + " " + flag, &out), 2) << flag << "\n" << out;
    EXPECT_EQ(out.rfind("vmap: error: " + flag.substr(0, flag.find(' ')) + " ", 0), 0u) << out;
  }
  std::string out;
  EXPECT_EQ(RunVmap(pair + " --camera 0,0,1", &out), 2) << out;
  EXPECT_NE(out.find("vmap: error:"), std::string::npos) << out;
}

}  // namespace
}  // namespace vmap
