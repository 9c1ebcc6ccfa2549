// End-to-end tests of the vmap binary: real sequences in every layout, and every kind of bad input.

#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::Quote;
using testing::RunVmap;

namespace {

fs::path Shared() { return testing::SharedDir(); }

// A synthetic sequence of `num_frames` written as an image folder at `directory`.
void WriteSyntheticInput(const fs::path& directory, int num_frames, double step = testing::SyntheticOptions().step) {
  testing::SyntheticOptions options;
  options.num_frames = num_frames;
  options.step = step;
  testing::WriteImageFolder(testing::RenderSyntheticSequence(options), directory);
}

// Calls `check` with every line of every command's --help.
void ForEveryHelpLine(const std::function<void(const std::string& command, const std::string& line)>& check) {
  for (const char* command :
       {"build", "localize", "route", "simulate", "info", "report", "eval", "sweep", "match", "draw", "weights"}) {
    std::string out;
    ASSERT_EQ(RunVmap(std::string(command) + " --help", &out), 0) << out;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);) check(command, line);
  }
}

}  // namespace

TEST(Cli, BuildsAndReadsBackAMapFromAVideo) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  std::string out;
  const fs::path map_dir = tmp.path() / "map";
  ASSERT_EQ(
      RunVmap("build " + Quote(Shared() / "data/lab_floor/lab_floor.mp4") + " -o " + Quote(map_dir) + " --last 239",
              &out),
      0)
      << out;
  EXPECT_NE(out.find("frames (n)      240"), std::string::npos) << out;
  const VisualMap map = ReadMap(map_dir);
  EXPECT_EQ(map.num_frames, 240);
  EXPECT_GE(map.key_images.size(), 2u);
  EXPECT_EQ(map.links.size(), map.key_images.size() - 1);
  for (const KeyImage& k : map.key_images) {
    const cv::Mat image = cv::imread((map_dir / k.image_file).string());
    EXPECT_EQ(image.size(), cv::Size(640, 480));
  }
  const auto options = nlohmann::json::parse(map.options_json);
  EXPECT_EQ(options["matcher"]["type"], "orb");
  EXPECT_EQ(options["verifier"]["method"], "magsac");
  EXPECT_EQ(options["source"]["last"], 239);
  ASSERT_EQ(RunVmap("info " + Quote(map_dir), &out), 0) << out;
  EXPECT_NE(out.find("key images (m)  " + std::to_string(map.key_images.size())), std::string::npos) << out;
  // No temporary directories left next to the map.
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

TEST(Cli, EveryDatasetLayoutBuilds) {
  SKIP_WITHOUT_SHARED();
  struct Case {
    std::string input, extra;
    int frames;
  };
  for (const Case& c : {Case{"data/rccar_room/images", "", 329}, Case{"data/redkitchen", "--last 299", 300},
                        Case{"data/kitti07", "", 160}}) {
    testing::ScopedTempDir tmp;
    std::string out;
    ASSERT_EQ(RunVmap("build " + Quote(Shared() / c.input) + " -o " + Quote(tmp.path() / "m") + " " + c.extra, &out), 0)
        << c.input << "\n"
        << out;
    const VisualMap map = ReadMap(tmp.path() / "m");
    EXPECT_EQ(map.num_frames, c.frames) << c.input;
    EXPECT_GE(map.key_images.size(), 2u) << c.input;
    EXPECT_LT(map.key_images.size(), static_cast<size_t>(c.frames)) << c.input;
    EXPECT_GE(map.key_images[1].timestamp, 0.0) << c.input;
  }
}

TEST(Cli, SweepWritesThePapersTable) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  std::string out;
  ASSERT_EQ(RunVmap("sweep " + Quote(Shared() / "data/rccar_room/images") + " --last 99 --thresholds 0.1:0.9:0.2 -o " +
                        Quote(tmp.path() / "sweep") + " --maps",
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("Best tau by Q"), std::string::npos) << out;
  std::ifstream in(tmp.path() / "sweep/sweep.json");
  const auto json = nlohmann::json::parse(in);
  ASSERT_EQ(json["rows"].size(), 5u);
  EXPECT_EQ(json["features_extracted"], 100);
  int previous = 0;
  for (const auto& row : json["rows"]) {
    EXPECT_GE(row["key_images"].get<int>(), previous);
    previous = row["key_images"].get<int>();
    const VisualMap map = ReadMap(tmp.path() / "sweep" / row["map"].get<std::string>());
    EXPECT_EQ(static_cast<int>(map.key_images.size()), row["key_images"].get<int>());
    // Each map records its own tau (vmap info, report and localize read it), not the default's 0.5.
    EXPECT_DOUBLE_EQ(RecordedOptionsFromJson(map.options_json, "map").builder.key_images.tau, row["tau"].get<double>());
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "sweep/sweep.csv"));
  EXPECT_TRUE(fs::exists(tmp.path() / "sweep/sweep.md"));
}

// A sweep's map at a tau is the map `vmap build --tau` makes (docs/sweep.md): the same key images, links and link
// analysis. The homography's share once followed the order of the estimate that decided a link, which depends on
// the thresholds it settled: kitti07's sweep and build differed on 6 of 47 links.
TEST(Cli, ASweepsMapIsTheMapOfItsTau) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  const std::string input = Quote(Shared() / "data/kitti07") + " --last 150 -q";
  std::string out;
  ASSERT_EQ(RunVmap("build " + input + " --tau 0.5 -o " + Quote(tmp.path() / "built"), &out), 0) << out;
  ASSERT_EQ(RunVmap("sweep " + input + " --thresholds 0.3,0.5,0.7 --maps -o " + Quote(tmp.path() / "sweep"), &out), 0)
      << out;
  const VisualMap built = ReadMap(tmp.path() / "built"), swept = ReadMap(tmp.path() / "sweep/tau_0.50");
  ASSERT_EQ(built.links.size(), swept.links.size());
  ASSERT_GE(built.links.size(), 10u);
  for (size_t i = 0; i < built.links.size(); ++i) {
    SCOPED_TRACE("link " + std::to_string(i));
    EXPECT_EQ(built.links[i].from_key, swept.links[i].from_key);
    EXPECT_EQ(built.links[i].num_verified, swept.links[i].num_verified);
    EXPECT_EQ(built.links[i].homography_share, swept.links[i].homography_share);
    EXPECT_EQ(built.links[i].planar, swept.links[i].planar);
  }
  // The sweep's own record names the τ it tried, not the matcher's default (0.5 here would look like one of them).
  std::ifstream in(tmp.path() / "sweep/sweep.json");
  const nlohmann::json sweep = nlohmann::json::parse(in);
  EXPECT_FALSE(sweep["options"].contains("tau")) << sweep["options"];
  EXPECT_EQ(sweep["options"]["thresholds"], nlohmann::json::array({0.3, 0.5, 0.7}));
}

TEST(Cli, LoftrBuildsAMapEndToEnd) {
#ifndef VMAP_WITH_TORCH
  GTEST_SKIP() << "built without LibTorch";
#endif
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(Shared() / "data/rccar_room/images") + " --last 39 --matcher loftr -o " +
                        Quote(tmp.path() / "m"),
                    &out),
            0)
      << out;
  const VisualMap map = ReadMap(tmp.path() / "m");
  EXPECT_EQ(map.num_frames, 40);
  EXPECT_GE(map.key_images.size(), 2u);
  EXPECT_EQ(nlohmann::json::parse(map.options_json)["matcher"]["type"], "loftr");
  // A link that is not broken passed the test: it has an F, verified by at least 8 matches that satisfy it
  // (within twice the verifier's 0.5 px threshold).
  int verified_links = 0;
  for (const Link& link : map.links) {
    EXPECT_EQ(static_cast<int>(link.correspondences.size()), link.num_tentative);
    if (link.below_tau) continue;
    ++verified_links;
    EXPECT_TRUE(link.has_fundamental);
    EXPECT_GE(link.num_verified, 8);
    ASSERT_LE(link.num_verified, static_cast<int>(link.correspondences.size()));
    for (int k = 0; k < link.num_verified; ++k) {
      const Correspondence& c = link.correspondences[k];
      EXPECT_LT(SampsonDistance(link.F, c.p0, c.p1), 1.0) << "link " << link.from_key << ", match " << k;
    }
  }
  EXPECT_GE(verified_links, 1);
  ASSERT_EQ(RunVmap("info " + Quote(tmp.path() / "m"), &out), 0) << out;
  EXPECT_NE(out.find("matcher         loftr"), std::string::npos) << out;
}

TEST(Cli, OneFrameSequenceIsAMapWithOneKeyImage) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 1);
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  const VisualMap map = ReadMap(tmp.path() / "m");
  EXPECT_EQ(map.key_images.size(), 1u);
  EXPECT_TRUE(map.links.empty());
}

// A tau that keeps most frames is said (the map is nearly the run itself); one that keeps few is not, nor --tau 1.
TEST(Cli, AMapOfMostFramesIsSaid) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 24, 0.08);
  const std::string build = "build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m");
  std::string out;
  ASSERT_EQ(RunVmap(build + " --tau 0.99", &out), 0) << out;
  ASSERT_GT(2 * ReadMap(tmp.path() / "m").key_images.size(), 24u) << out;
  EXPECT_NE(out.find("frames became key images at tau 0.99"), std::string::npos) << out;
  for (const char* tau : {"0.3", "1"}) {
    ASSERT_EQ(RunVmap(build + " --tau " + tau, &out), 0) << out;
    EXPECT_EQ(out.find("frames became key images"), std::string::npos) << out;
  }
}

TEST(Cli, VerboseLogSaysWhyEachKeyImageWasChosenAndQuietSaysNothing) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 30, 0.08);
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m") + " --tau 0.8 -v", &out), 0)
      << out;
  EXPECT_NE(out.find("key image 0 = frame 0 (first frame)"), std::string::npos) << out;
  EXPECT_NE(out.find("< tau"), std::string::npos) << out;
  EXPECT_NE(out.find("(final frame)"), std::string::npos) << out;
  ASSERT_EQ(RunVmap("-q build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  EXPECT_EQ(out.find("[debug]"), std::string::npos) << out;
  EXPECT_EQ(out.find("\r"), std::string::npos) << "no progress line when not on a terminal";
}

TEST(Cli, ProgressLineOnATerminalOnly) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "util-linux `script` is missing";
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 40);
  // `script` gives the binary a pseudo-terminal, as an interactive user would.
  auto on_terminal = [&](const std::string& flags) {
    std::ofstream(tmp.path() / "run.sh") << testing::Quote(testing::VmapBinary()) << " " << flags << " build '"
                                         << (tmp.path() / "in").string() << "' -o '" << (tmp.path() / "m").string()
                                         << "'\n";
    FILE* pipe = popen(("script -qec 'sh " + (tmp.path() / "run.sh").string() + "' /dev/null").c_str(), "r");
    std::string text;
    char buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) text.append(buffer, n);
    pclose(pipe);
    return text;
  };
  const std::string interactive = on_terminal("");
  EXPECT_NE(interactive.find("/40 frames"), std::string::npos) << interactive;
  EXPECT_NE(interactive.find("frames/s"), std::string::npos) << interactive;
  const std::string quiet = on_terminal("--quiet");
  EXPECT_EQ(quiet.find("/40 frames"), std::string::npos) << quiet;
  EXPECT_NE(quiet.find("key images (m)"), std::string::npos) << quiet;
}

TEST(Cli, BadInputGivesAClearErrorAndWritesNothing) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 4);
  fs::create_directories(tmp.path() / "empty");
  std::ofstream(tmp.path() / "broken.mp4") << std::string(4096, '\x42');
  fs::create_directories(tmp.path() / "corrupt");
  for (const char* name : {"a.png", "b.png", "c.png"}) std::ofstream(tmp.path() / "corrupt" / name) << "not an image";
  struct Case {
    std::string arguments;
    std::string expected;  // part of the message
  };
  const std::string in = Quote(tmp.path() / "in");
  const std::string out_dir = " -o " + Quote(tmp.path() / "out");
  const std::vector<Case> cases = {
      {"build " + Quote(tmp.path() / "nothing_here") + out_dir, "nothing_here' does not exist"},
      {"build " + Quote(tmp.path() / "empty") + out_dir, "holds no images"},
      {"build " + Quote(tmp.path() / "broken.mp4") + out_dir, "cannot open video"},
      {"build " + Quote(tmp.path() / "corrupt") + out_dir, "none of the 3 images"},
      {"build " + Quote(tmp.path() / "in" / "frame_1.png") + out_dir, "is a single image"},
      {"build " + in + out_dir + " --tau 0", "outside (0, 1]"},
      {"build " + in + out_dir + " --tau 1.5", "outside (0, 1]"},
      {"build " + in + out_dir + " --verifier lmeds", "unknown verifier 'lmeds'"},
      {"build " + in + out_dir + " --matcher sift", "--matcher 'sift' is unknown; use orb, aliked"},
      {"build " + in + out_dir + " --matcher ORB",
       "--matcher 'ORB' is unknown; matchers are named in lower case: use orb"},
      {"build " + in + out_dir + " --similarity cosine", "unknown similarity"},
      {"build " + in + out_dir + " --format tum", "rgb.txt"},
      {"build " + in + out_dir + " --stride 0", "--stride"},
      {"build " + in + out_dir + " --first 10", "leaves none"},
      {"info " + Quote(tmp.path() / "in"), "map.json is missing"},
  };
  for (const Case& c : cases) {
    std::string output;
    EXPECT_EQ(RunVmap(c.arguments, &output), 2) << c.arguments << "\n" << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << c.arguments << "\n" << output;
    EXPECT_FALSE(fs::exists(tmp.path() / "out")) << c.arguments;
  }
  // Nothing half-written was left next to the output either.
  for (const auto& entry : fs::directory_iterator(tmp.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".out."), std::string::npos) << entry.path();
  }
}

// The library names a bad option by its field ("link_analysis.pose.threshold"); the command names the flag that
// set it, for nested fields, for the other fields a message names, and for each matcher model's options.
TEST(Cli, OptionErrorsNameTheFlagsThatSetTheFields) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 4);
  const std::string build = "build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "out") + " ";
  struct Case {
    std::string arguments;
    std::string message;  // the whole error line
  };
  const std::vector<Case> cases = {
      {build + "--pose-threshold -1", "vmap: error: --pose-threshold -1 px is outside (0, 100] (default 1 px)\n"},
      {build + "--max-translation-sigma 0",
       "vmap: error: --max-translation-sigma 0 deg is outside (0, 180] (default 3 deg)\n"},
      {build + "--min-translation-parallax -1",
       "vmap: error: --min-translation-parallax -1 px is less than 0 (default 3 px)\n"},
      {build + "--threads 999", "vmap: error: --threads 999 is outside [0, 256] (default 0; 0: one per core)\n"},
      {build + "--min-key-displacement 200",
       "vmap: error: --min-key-displacement 200 px is outside [0, 100] (default 1 px; 0 turns the check off)\n"},
      {build + "--exhaustive --search bisect",
       "vmap: error: --exhaustive is the paper's frame-by-frame scan and --search bisect skips frames; drop one\n"},
      {build + "--first 3 --last 1", "vmap: error: --last 1 is before --first 3\n"},
      {build + "--seed -3", "vmap: error: --seed -3 is less than 0 (default 0)\n"},
      {build + "--stream-timeout 0", "vmap: error: --stream-timeout 0 s is outside (0, 3600] (default 10 s)\n"},
      {build + "--xfeat-top-k 0", "vmap: error: --xfeat-top-k 0 is less than 1 (default 4096)\n"},
      {build + "--aliked-top-k -1",
       "vmap: error: --aliked-top-k must be >= 0 (0 = threshold mode with --aliked-score-threshold; default 1000)\n"},
      {"match " + Quote(tmp.path() / "in/frame_0.png") + " " + Quote(tmp.path() / "in/frame_1.png") + " --confidence 2",
       "vmap: error: --confidence 2 is outside (0, 1) (default 0.999)\n"},
      // A flag of a matcher the run does not use was taken and ignored.
      {build + "--aliked-top-k 5",
       "vmap: error: --aliked-top-k is an option of aliked, and the matcher is orb: drop it, or give --matcher "
       "aliked\n"},
      {build + "--matcher xfeat --loftr-size 320",
       "vmap: error: --loftr-size is an option of loftr, and the matcher is xfeat: drop it, or give --matcher loftr\n"},
      {"sweep " + Quote(tmp.path() / "in") + " --weights " + Quote(tmp.path() / "w.pt"),
       "vmap: error: --weights is an option of aliked, loftr, xfeat, and the matcher is orb: drop it, or give "
       "--matcher aliked\n"},
  };
  for (const Case& c : cases) {
    std::string output;
    EXPECT_EQ(RunVmap(c.arguments, &output), 2) << c.arguments << "\n" << output;
    EXPECT_EQ(output, c.message) << c.arguments;
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
}

TEST(Cli, ReplacesAnOlderMapButNeverAFolderOfTheUser) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 5);
  std::string out;
  const std::string build = "build " + Quote(tmp.path() / "in") + " -o ";
  ASSERT_EQ(RunVmap(build + Quote(tmp.path() / "m"), &out), 0) << out;
  ASSERT_EQ(RunVmap(build + Quote(tmp.path() / "m") + " --tau 0.9", &out), 0) << out;
  EXPECT_NEAR(nlohmann::json::parse(ReadMap(tmp.path() / "m").options_json)["tau"].get<double>(), 0.9, 1e-12);
  fs::create_directories(tmp.path() / "documents");
  std::ofstream(tmp.path() / "documents" / "notes.txt") << "keep me";
  EXPECT_EQ(RunVmap(build + Quote(tmp.path() / "documents"), &out), 2) << out;
  EXPECT_NE(out.find("will not replace it"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(tmp.path() / "documents" / "notes.txt"));
}

TEST(Cli, TruncatedVideoIsAClearError) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  std::ifstream in(Shared() / "data/lab_floor/lab_floor.mp4", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(tmp.path() / "cut.mp4", std::ios::binary) << bytes.substr(0, bytes.size() / 3);
  std::string out;
  EXPECT_EQ(RunVmap("build " + Quote(tmp.path() / "cut.mp4") + " -o " + Quote(tmp.path() / "m"), &out), 2) << out;
  EXPECT_NE(out.find("cut.mp4"), std::string::npos) << out;
  EXPECT_NE(out.find("truncated"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(tmp.path() / "m"));
}

TEST(Cli, DifferentFrameSizesWarnOrFailWhenStrict) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 5);
  cv::imwrite((tmp.path() / "in/frame_3.png").string(), cv::Mat(100, 150, CV_8UC3, cv::Scalar(90, 90, 90)));
  std::string out;
  EXPECT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  EXPECT_NE(out.find("resizing it"), std::string::npos) << out;
  EXPECT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m2") + " --strict", &out), 2)
      << out;
  EXPECT_NE(out.find("frame_3.png"), std::string::npos) << out;
}

// `vmap --help` lists the commands under headings, the teach-and-repeat workflow first; a command's --help lists its
// flags under the headings of its options' field lists, what a user sets every day before the localizer's rules.
// Every number a flag takes is bounded (promise 5), and its help says the values: "--tau FLOAT in (0, 1]".
TEST(Cli, EveryNumericFlagsHelpSaysTheValuesItTakes) {
  const std::regex unbounded(R"(^\s+(-[a-zA-Z], )?(--[a-z0-9-]+) (INT|FLOAT)(=|\s*$|\s\s))");
  int build_numeric = 0;
  ForEveryHelpLine([&](const std::string& command, const std::string& line) {
    std::smatch found;
    if (std::regex_search(line, found, unbounded)) ADD_FAILURE() << command << " " << found[2] << ": " << line;
    if (command == "build" && (line.find(" INT ") != std::string::npos || line.find(" FLOAT ") != std::string::npos)) {
      ++build_numeric;
    }
  });
  EXPECT_GT(build_numeric, 20);
}

TEST(Cli, HelpNamesEverySwitchAsItIsTyped) {
  // CLI11 alone writes "--no-odometry{false}": the value the switch stores, which no user types.
  const std::regex flag_column(R"(^\s+(-[a-zA-Z],)?--[a-z0-9-]+\{)");
  ForEveryHelpLine([&](const std::string& command, const std::string& line) {
    if (std::regex_search(line, flag_column)) ADD_FAILURE() << command << ": " << line;
  });
  std::string out;
  ASSERT_EQ(RunVmap("simulate --help", &out), 0) << out;
  EXPECT_NE(out.find("  --no-odometry "), std::string::npos) << out;
}

// A frame number copied from a file name (000010.png) is that frame: CLI11 alone read "010" as octal 8, "09" as no
// number, and "0x10" as 16.
TEST(Cli, IntegersAreDecimalWithOrWithoutLeadingZeros) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 14);
  std::string out;
  ASSERT_EQ(
      RunVmap("build " + Quote(tmp.path() / "in") + " --first 010 --last 0013 -q -o " + Quote(tmp.path() / "m"), &out),
      0)
      << out;
  EXPECT_EQ(ReadMap(tmp.path() / "m").key_images.front().source_index, 10);
  ASSERT_EQ(
      RunVmap("build " + Quote(tmp.path() / "in") + " --first 09 --last 13 -q -o " + Quote(tmp.path() / "m"), &out), 0)
      << out;
  EXPECT_EQ(ReadMap(tmp.path() / "m").key_images.front().source_index, 9);
  EXPECT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " --stride 0x2 -o " + Quote(tmp.path() / "x"), &out), 2);
  EXPECT_NE(out.find("--stride: 0x2 is not a decimal integer"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(tmp.path() / "x"));
}

// A timestamps file that leaves a frame without a time gives the frames none, and says so: it was silent.
TEST(Cli, ATimestampsFileThatMissesAFrameIsSaid) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 4);
  std::ofstream(tmp.path() / "in" / "timestamps.txt") << "frame_1.png 0.0\nframe_2.png nan\nframe_3.png 0.2\n"
                                                         "frame_4.png 0.3\n";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  EXPECT_NE(out.find("gives no time to image 'frame_2.png' (line 2 is no 'NAME SECONDS')"), std::string::npos) << out;
  EXPECT_LT(ReadMap(tmp.path() / "m").key_images.front().timestamp, 0.0) << "no frame has a time";
}

// CLI11's words where they read badly: a flag given twice ("At Most 1 required but received 2"), and arguments not
// expected, which it listed backwards ("0.3 --tua").
TEST(Cli, AFlagGivenTwiceAndArgumentsNotExpectedAreSaidPlainly) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 2);
  const std::string build = "build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m");
  std::string out;
  EXPECT_EQ(RunVmap(build + " --last 1 --last 0", &out), 2);
  EXPECT_NE(out.find("vmap: error: --last is given 2 times; give it once"), std::string::npos) << out;
  EXPECT_EQ(RunVmap(build + " --tua 0.3", &out), 2);
  EXPECT_NE(out.find("these arguments were not expected: --tua 0.3;"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(tmp.path() / "m"));
  // The flag not expected is said before the input it left missing.
  EXPECT_EQ(RunVmap("build -x", &out), 2);
  EXPECT_NE(out.find("this argument was not expected: -x;"), std::string::npos) << out;
  EXPECT_EQ(RunVmap("build", &out), 2);
  EXPECT_NE(out.find("input is required"), std::string::npos) << out;
}

TEST(Cli, HelpListsCommandsAndFlagsUnderHeadings) {
  std::string out;
  ASSERT_EQ(RunVmap("--help", &out), 0) << out;
  // `vmap` alone prints the same list, not an error.
  std::string bare;
  ASSERT_EQ(RunVmap("", &bare), 0) << bare;
  EXPECT_EQ(bare, out);
  const std::vector<std::string> in_order = {"Teach and repeat:", "  build",         "  localize",
                                             "  simulate",        "Look into a map", "  info",
                                             "  match",           "Set up:",         "  weights"};
  size_t at = 0;
  for (const std::string& text : in_order) {
    const size_t found = out.find(text, at);
    ASSERT_NE(found, std::string::npos) << text << " after position " << at << " in\n" << out;
    at = found;
  }
  ASSERT_EQ(RunVmap("localize --help", &out), 0) << out;
  at = 0;
  for (const char* text :
       {"Output:", "  --csv", "Input:", "  --first", "Route and odometry:", "  --from", "  --odometry ",
        "Start: where on the route", "  --start-key", "Acceptance:", "Rules across seasons and lighting",
        "  --no-doubt-jump-back", kRunSection, "  --threads", "  --no-cache"}) {
    const size_t found = out.find(text, at);
    ASSERT_NE(found, std::string::npos) << text << " after position " << at << " in\n" << out;
    at = found;
  }
  // A mistyped command is named, with the commands there are; a global flag before the command is no command.
  ASSERT_EQ(RunVmap("-q buidl x.mp4", &out), 2) << out;
  EXPECT_NE(out.find("vmap: error: 'buidl' is not a vmap command; the commands are build, localize, route"),
            std::string::npos)
      << out;
  ASSERT_EQ(RunVmap("-q info --help", &out), 0) << out;
}

}  // namespace vmap
