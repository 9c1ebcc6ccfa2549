// The promises of docs/promises.md on errors, each tested on the binary with several inputs:
// 4. every error is vmap's: "vmap: error: ..." naming the file, status 2; bad frames are skipped and counted;
//    file names that are not UTF-8 work;
// 5. every numeric option has a range, checked before any work.

#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/file_name_encoding.h"
#include "vmap/map/map_io.h"
#include "vmap/testing/promises_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::BuildMapWithBinary;
using testing::EntriesStartingWith;
using testing::Quote;
using testing::ReadText;
using testing::RunVmap;
using testing::WriteSyntheticInput;

namespace {

// The CPU time (user and system) of this process's children that have ended and been waited for.
double ChildrenCpuSeconds() {
  struct rusage usage {};
  getrusage(RUSAGE_CHILDREN, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

}  // namespace

// ---- 4. Every error is vmap's -------------------------------------------------------------------------------

// A file name may hold an ESC or a carriage return: warnings and errors print it escaped, so that it can neither
// drive the terminal nor overwrite the line that names it.
TEST(Promises, ControlCharactersInFileNamesReachTheTerminalEscaped) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 8);
  std::ofstream(tmp.path() / "in/frame_5\x1b[2J\r.png", std::ios::trunc) << "garbage";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  EXPECT_NE(out.find("frame_5\\x1b[2J\\r.png"), std::string::npos) << out;
  EXPECT_EQ(out.find_first_of("\x1b\r"), std::string::npos) << out;
  ASSERT_EQ(RunVmap("info " + Quote(tmp.path() / "no\x1b]0;title\x07map"), &out), 2) << out;
  EXPECT_NE(out.find("no\\x1b]0;title\\x07map"), std::string::npos) << out;
  EXPECT_EQ(out.find_first_of("\x1b\x07"), std::string::npos) << out;
}

TEST(Promises, BadFramesAreSkippedWithAWarningAndCounted) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 10);
  cv::imwrite((tmp.path() / "in/frame_3.png").string(), cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(9)));
  cv::imwrite((tmp.path() / "in/frame_6.png").string(), cv::Mat(2, 700, CV_8UC3, cv::Scalar::all(9)));
  std::ofstream(tmp.path() / "in/frame_8.png", std::ios::trunc) << "garbage";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  for (const char* name : {"frame_3.png", "frame_6.png", "frame_8.png"}) {
    EXPECT_NE(out.find(std::string(name) + "': "), std::string::npos) << name << "\n" << out;
  }
  EXPECT_NE(out.find("(3 unusable frames skipped)"), std::string::npos) << out;
  const VisualMap map = ReadMap(tmp.path() / "m");
  EXPECT_EQ(map.skipped_frames, 3);
  EXPECT_EQ(map.num_frames, 7);
  // The first frame bad too: the first good one sets the size.
  cv::imwrite((tmp.path() / "in/frame_1.png").string(), cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(9)));
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "m"), &out), 0) << out;
  EXPECT_EQ(ReadMap(tmp.path() / "m").skipped_frames, 4);
}

TEST(Promises, FileNamesThatAreNotUtf8Work) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  // Latin-1 names, as an old camera or a Windows share writes them, and a '%'.
  const std::vector<std::string> names = {"caf\xE9_1.png",  "caf\xE9_2.png",  "100%_3.png",
                                          "\xFF\xFE_4.png", "na\xEFve_5.png", "ok_6.png"};
  for (int i = 0; i < 6; ++i)
    fs::rename(tmp.path() / "in" / ("frame_" + std::to_string(i + 1) + ".png"), tmp.path() / "in" / names[i]);
  const fs::path input = tmp.path() / "in\xE9";
  fs::rename(tmp.path() / "in", input);
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(input) + " -o " + Quote(tmp.path() / "m") + " --tau 0.99 --report", &out), 0)
      << out;
  const std::string text = ReadText(tmp.path() / "m/map.json");
  EXPECT_TRUE(IsValidUtf8(text));
  EXPECT_NO_THROW(nlohmann::json::parse(text));
  EXPECT_NE(text.find("caf%E9_1.png"), std::string::npos);
  const VisualMap map = ReadMap(tmp.path() / "m");
  EXPECT_EQ(map.input.path, input.string());
  std::set<std::string> sources;
  for (const KeyImage& k : map.key_images) sources.insert(k.source_name);
  EXPECT_TRUE(sources.count("caf\xE9_1.png")) << "the first frame is a key image";
  for (const std::string& name : sources) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << "not round-tripped: " << name;
  }
  ASSERT_EQ(RunVmap("info " + Quote(tmp.path() / "m"), &out), 0) << out;
  ASSERT_EQ(RunVmap("sweep " + Quote(input) + " --thresholds 0.5 -o " + Quote(tmp.path() / "s"), &out), 0) << out;
  EXPECT_TRUE(IsValidUtf8(ReadText(tmp.path() / "s/sweep.json")));
  ASSERT_EQ(RunVmap("match " + Quote(input / names[0]) + " " + Quote(input / names[1]) + " --json " +
                        Quote(tmp.path() / "match.json"),
                    &out),
            0)
      << out;
  const auto match = nlohmann::json::parse(ReadText(tmp.path() / "match.json"));
  EXPECT_EQ(DecodeFileName(match["image0"]["path"].get<std::string>()), (input / names[0]).string());
}

TEST(Promises, LibraryErrorsBecomeVmapErrorsNamingTheFile) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 6);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "m");
  // An image whose header announces 40000 x 40000 pixels: OpenCV refuses to decode it with an exception.
  testing::WritePngHeader(tmp.path() / "big.png", 40000, 40000);
  cv::imwrite((tmp.path() / "tiny.png").string(), cv::Mat(1, 1, CV_8U, cv::Scalar(1)));
  // A key image that does not decode any more (same size header, damaged data).
  fs::copy(tmp.path() / "m", tmp.path() / "damaged", fs::copy_options::recursive);
  const VisualMap map = ReadMap(tmp.path() / "m");
  {
    std::fstream key(tmp.path() / "damaged" / map.key_images[0].image_file,
                     std::ios::in | std::ios::out | std::ios::binary);
    key.seekp(40);
    key.write(std::string(200, '\x55').data(), 200);
  }
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {"match " + Quote(tmp.path() / "big.png") + " " + Quote(tmp.path() / "tiny.png"),
       "image '" + (tmp.path() / "big.png").string() + "' is 40000x40000 (from its header), more than"},
      {"match " + Quote(tmp.path() / "in/frame_1.png") + " " + Quote(tmp.path() / "tiny.png"),
       "tiny.png' is 1x1 (from its header), smaller than 32 pixels"},
      {"report " + Quote(tmp.path() / "damaged"), map.key_images[0].image_file},
      {"draw " + Quote(tmp.path() / "damaged") + " --link 0 -o " + Quote(tmp.path() / "f.png"),
       map.key_images[0].image_file},
      {"draw " + Quote(tmp.path() / "m") + " --link 0 -o " + Quote(tmp.path() / "m/keys/000000.png"),
       "lies inside the map's keys"},
      {"match " + Quote(tmp.path() / "in/frame_1.png") + " " + Quote(tmp.path() / "in/frame_2.png") + " --json " +
           Quote(tmp.path() / "in/frame_2.png"),
       "would overwrite the input image"},
  };
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_EQ(out.rfind("vmap: error: "), out.find("vmap: error: ")) << "one error line\n" << out;
    EXPECT_NE(out.find("vmap: error: "), std::string::npos) << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "damaged/report.html"));
  EXPECT_FALSE(fs::exists(tmp.path() / "f.png"));
}

// ---- 5. Bounded options -------------------------------------------------------------------------------------

TEST(Promises, AbsurdOptionsAreRefusedBeforeAnyWork) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 4);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "m");
  const std::string build = "build " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "out") + " ";
  const std::string sweep = "sweep " + Quote(tmp.path() / "in") + " -o " + Quote(tmp.path() / "out") + " ";
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {build + "--threads 40000", "--threads 40000 is outside [0, 256]"},
      {build + "--threads -1", "--threads -1 is outside [0, 256]"},
      {build + "--threads abc", "--threads"},
      {build + "--threads 99999999999999", "--threads"},
      {sweep + "--thresholds 0.1:0.9:1e-6", "gives 800001 thresholds, more than 100"},
      {sweep + "--thresholds 0.1:0.9:1e-300", "gives 8e+299 thresholds, more than 100"},
      {sweep + "--thresholds 0.5,0.5", "gives tau = 0.5 twice"},
      {sweep + "--thresholds nan:1:0.1", "must be start:stop:step"},
      {sweep + "--thresholds 0.1:0.9:inf", "must be start:stop:step"},
      {sweep + "--thresholds 0.501,0.502 --maps", "round to the same map folder 'tau_0.50'"},
      {build + "--resize 100000x100000", "--resize 100000x100000: each side must be 32 to 16384"},
      {build + "--resize 10", "the longest side must be 32 to 16384"},
      {build + "--loftr-size 100000", "--loftr-size 100000 is outside [32, 4096]"},
      {build + "--ratio nan", "--ratio nan is outside [0, 1]"},
      {build + "--ratio 1.5", "--ratio 1.5 is outside [0, 1]"},
      {build + "--loftr-threshold nan", "--loftr-threshold nan is outside [-1, 1]"},
      {build + "--loftr-threshold -inf", "--loftr-threshold -inf is outside [-1, 1]"},
      {build + "--loftr-threshold -2", "--loftr-threshold -2 is outside [-1, 1]"},
      {build + "--loftr-threads 100000", "--loftr-threads 100000 is outside [0, 256]"},
      {build + "--matcher xfeat --xfeat-threads 10000", "--xfeat-threads 10000 is outside [0, 256]"},
      {build + "--matcher aliked --aliked-threads 100000", "--aliked-threads 100000 is outside [0, 256]"},
      {build + "--last -5", "--last -5 is not a frame"},
      {build + "--first -1", "--first -1 is less than 0"},
      {build + "--stride 0", "--stride 0 is less than 1"},
      {build + "--tau nan", "outside (0, 1]"},
      {build + "--tau inf", "outside (0, 1]"},
      {build + "--threshold nan", "--threshold nan px is outside (0, 100]"},
      {build + "--threshold 1e9", "--threshold 1000000000 px is outside (0, 100]"},
      {build + "--confidence nan", "--confidence nan is outside (0, 1)"},
      {build + "--max-iters 0", "--max-iters 0 is outside [1, 10000000]"},
      {build + "--max-iters 2000000000", "--max-iters 2000000000 is outside [1, 10000000]"},
      {build + "--seed -3", "--seed -3 is less than 0"},
      {build + "--orb-features 0", "--orb-features 0 is outside [1, 100000]"},
      {build + "--orb-features 100000000", "--orb-features 100000000 is outside [1, 100000]"},
      {build + "--orb-levels 100", "--orb-levels 100 is outside [1, 32]"},
      {build + "--orb-scale-factor nan", "--orb-scale-factor nan is outside (1, 4]"},
      {build + "--orb-fast-threshold 300", "--orb-fast-threshold 300 is outside [1, 255]"},
      {build + "--orb-edge-threshold -1", "--orb-edge-threshold -1 px is outside [0, 1000]"},
      {build + "--frobnicate", "--frobnicate"},
      {"report " + Quote(tmp.path() / "m") + " --thumbnail-width 1", "--thumbnail-width"},
      {"draw " + Quote(tmp.path() / "m") + " --link 0 -o " + Quote(tmp.path() / "out.png") + " --width 5",
       "--width is 5; use 0"},
      {"build", "input is required"},
  };
  for (const Case& c : cases) {
    std::string out;
    const double cpu_before = ChildrenCpuSeconds();
    EXPECT_EQ(RunVmap(c.arguments, &out), 2) << c.arguments << "\n" << out;
    EXPECT_EQ(out.find("vmap: error: "), 0u) << c.arguments << "\n" << out;
    EXPECT_NE(out.find(c.expected), std::string::npos) << c.arguments << "\n" << out;
    EXPECT_FALSE(fs::exists(tmp.path() / "out")) << c.arguments;
    EXPECT_FALSE(fs::exists(tmp.path() / "out.png")) << c.arguments;
    // CPU time, not wall time, as for the untrusted maps: a loaded machine stretches the wall time, not the work.
    EXPECT_LT(ChildrenCpuSeconds() - cpu_before, 10.0) << c.arguments;
  }
  EXPECT_TRUE(EntriesStartingWith(tmp.path(), ".").empty());
  // The limits themselves are accepted, and so is --last -1 ("to the end").
  std::string out;
  EXPECT_EQ(RunVmap(build + "--threads 256 --last -1 --ratio 1 --orb-levels 32 --resize 32x32", &out), 0) << out;
  // --help and --version are not errors.
  EXPECT_EQ(RunVmap("--help", &out), 0) << out;
  EXPECT_EQ(RunVmap("build --help", &out), 0) << out;
  EXPECT_NE(out.find("--threads"), std::string::npos);
  EXPECT_EQ(RunVmap("--version", &out), 0) << out;
  EXPECT_EQ(out.rfind("vmap ", 0), 0u) << out;
}

}  // namespace vmap
