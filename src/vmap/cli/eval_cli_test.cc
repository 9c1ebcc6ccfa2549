// End-to-end tests of `vmap eval`, of the camera options of `vmap build`, of `vmap sweep --gt` and of the
// report's link table, on the real sequences with ground truth and on synthetic ones.

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/evaluation/evaluation_json.h"
#include "vmap/evaluation/map_evaluation.h"
#include "vmap/map/map_io.h"
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

nlohmann::json ReadJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

testing::SyntheticSequence Synthetic() {
  testing::SyntheticOptions options;
  options.num_frames = 30;
  options.step = 0.06;
  options.yaw_per_frame = 0.01;
  return testing::RenderSyntheticSequence(options);
}

}  // namespace

TEST(EvalCli, Kitti07LinksAreUsableAndTheReportShowsThem) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(Shared() / "data/kitti07") + " --last 59 -q -o " + Quote(map), &out), 0) << out;
  const VisualMap built = ReadMap(map);
  ASSERT_TRUE(built.input.camera);  // from calib.txt
  EXPECT_EQ(built.input.camera->model, CameraModel::kSimplePinhole);
  for (const Link& link : built.links) EXPECT_TRUE(link.has_pose);

  ASSERT_EQ(RunVmap("eval " + Quote(map) + " --json " + Quote(tmp.path() / "eval.json"), &out), 0) << out;
  EXPECT_NE(out.find("usable links"), std::string::npos) << out;
  EXPECT_NE(out.find("| link |"), std::string::npos) << out;
  EXPECT_NE(out.find("written to      " + (tmp.path() / "eval.json").string() + "\n"), std::string::npos) << out;
  const nlohmann::json doc = ReadJson(tmp.path() / "eval.json");
  const nlohmann::json& summary = doc["summary"];
  for (const char* field : {"links", "usable_links", "rotation_error_deg_median", "translation_error_deg_median"}) {
    EXPECT_TRUE(summary.contains(field)) << field;
  }
  EXPECT_EQ(summary["links"].get<int>(), static_cast<int>(built.links.size()));
  EXPECT_EQ(summary["evaluated_links"], summary["links"]);
  // The development sequence's default map: every link usable (docs/measurements/links.md).
  EXPECT_GE(summary["usable_links"].get<double>(), 0.95 * summary["links"].get<double>()) << out;
  EXPECT_LT(summary["rotation_error_deg_median"].get<double>(), 0.5);
  EXPECT_EQ(doc["ground_truth"]["format"], "kitti");
  // Also written into the map, where the report finds it.
  ASSERT_TRUE(fs::exists(map / kEvaluationFileName));
  EXPECT_EQ(ReadEvaluation((map / kEvaluationFileName).string()).summary.usable_links, summary["usable_links"]);
  // --json naming the map's own eval.json writes it once, as the map's; with --no-save it is refused.
  fs::remove(map / kEvaluationFileName);
  ASSERT_EQ(RunVmap("eval " + Quote(map) + " --json " + Quote(map / ".." / "map" / kEvaluationFileName), &out), 0)
      << out;
  EXPECT_EQ(ReadJson(map / kEvaluationFileName)["summary"], summary);
  EXPECT_EQ(RunVmap("eval " + Quote(map) + " --no-save --json " + Quote(map / kEvaluationFileName), &out), 2);
  EXPECT_NE(out.find("is the map's own evaluation, and --no-save asks to leave that as it is"), std::string::npos)
      << out;

  ASSERT_EQ(RunVmap("report " + Quote(map) + " --no-video", &out), 0) << out;
  std::ifstream in(map / "report.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("id=\"link-table\""), std::string::npos);
  EXPECT_NE(html.find("usable links"), std::string::npos);
  EXPECT_NE(html.find("rotation error"), std::string::npos);
  // `vmap info` names the camera.
  ASSERT_EQ(RunVmap("info " + Quote(map), &out), 0) << out;
  EXPECT_NE(out.find("SIMPLE_PINHOLE"), std::string::npos) << out;
}

// Ground truth that does not belong to the map is said so, whatever gives its key images poses: an image folder
// numbered from 1 (ffmpeg's %06d) is matched to KITTI poses by position, not by its files' numbers (a frame off), the
// table names the input frames the poses are of, and ground truth of another run warns of its matches.
TEST(EvalCli, GroundTruthIsMatchedToTheMapsOwnFramesOrSaidNotToFit) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  const fs::path folder = tmp.path() / "numbered_from_1";
  fs::create_directories(folder);
  for (int i = 0; i <= 40; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.jpg", i);
    char link[32];
    std::snprintf(link, sizeof(link), "%06d.jpg", i + 1);
    fs::create_symlink(Shared() / "data/kitti07/image_0" / name, folder / link);
  }
  const std::string camera = " --camera 707.0912,707.0912,601.8873,183.1104";
  const fs::path map = tmp.path() / "map";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(folder) + " -q -o " + Quote(map), &out), 0) << out;
  ASSERT_EQ(RunVmap("eval " + Quote(map) + " --gt " + Quote(Shared() / "data/kitti07/poses.txt") + camera, &out), 0)
      << out;
  EXPECT_GE(ReadJson(map / "eval.json")["summary"]["verified_within_threshold_mean"].get<double>(), 0.9) << out;
  EXPECT_EQ(out.find("of the verified matches lie within"), std::string::npos) << out;
  // vmap sweep --gt matches them alike: every link usable, as the map's eval finds.
  ASSERT_EQ(RunVmap("sweep " + Quote(folder) + " --thresholds 0.5 --gt " + Quote(Shared() / "data/kitti07/poses.txt") +
                        camera + " -q -o " + Quote(tmp.path() / "sweep"),
                    &out),
            0)
      << out;
  const nlohmann::json swept = ReadJson(tmp.path() / "sweep/sweep.json")["rows"][0];
  EXPECT_EQ(swept["usable_links"], ReadJson(map / "eval.json")["summary"]["usable_links"]) << swept.dump();
  EXPECT_GE(swept["usable_links"].get<int>(), 1) << swept.dump();

  const fs::path strided = tmp.path() / "strided";
  ASSERT_EQ(
      RunVmap("build " + Quote(Shared() / "data/kitti07") + " --first 20 --last 60 --stride 2 -q -o " + Quote(strided),
              &out),
      0)
      << out;
  ASSERT_EQ(RunVmap("eval " + Quote(strided), &out), 0) << out;
  EXPECT_NE(out.find("|     20-"), std::string::npos) << out;  // link 0 from input frame 20, the map's frame 0

  // redkitchen's ground truth against kitti07's times: poses, but the matches lie off its epipolar lines.
  ASSERT_EQ(
      RunVmap("eval " + Quote(strided) + " --gt " + Quote(Shared() / "data/redkitchen/groundtruth.txt") + " --no-save",
              &out),
      0)
      << out;
  EXPECT_NE(out.find("of the verified matches lie within 2 px of the ground truth's epipolar lines"), std::string::npos)
      << out;
}

TEST(EvalCli, RedkitchenIsEvaluatedByTimestamp) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(Shared() / "data/redkitchen") + " --last 119 -q -o " + Quote(map), &out), 0)
      << out;
  ASSERT_EQ(RunVmap("eval " + Quote(map) + " --no-table --no-save --json " + Quote(tmp.path() / "e.json"), &out), 0)
      << out;
  EXPECT_FALSE(fs::exists(map / kEvaluationFileName));
  const nlohmann::json doc = ReadJson(tmp.path() / "e.json");
  EXPECT_EQ(doc["ground_truth"]["format"], "tum");
  EXPECT_GT(doc["summary"]["links"].get<int>(), 3);
  EXPECT_EQ(doc["summary"]["evaluated_links"], doc["summary"]["links"]);
  // Thresholds are options, recorded with the result.
  ASSERT_EQ(RunVmap("eval " + Quote(map) + " --no-table --no-save --max-rotation-error 0.01 --json " +
                        Quote(tmp.path() / "strict.json"),
                    &out),
            0)
      << out;
  const nlohmann::json strict = ReadJson(tmp.path() / "strict.json");
  EXPECT_EQ(strict["options"]["max_rotation_error_deg"], 0.01);
  EXPECT_LT(strict["summary"]["usable_links"].get<int>(), doc["summary"]["usable_links"].get<int>());
}

TEST(EvalCli, SweepWithGroundTruthAddsAUsableLinksColumn) {
  SKIP_WITHOUT_SHARED();
  testing::ScopedTempDir tmp;
  std::string out;
  ASSERT_EQ(RunVmap("sweep " + Quote(Shared() / "data/kitti07") + " --last 39 --thresholds 0.4,0.6 --gt -q -o " +
                        Quote(tmp.path() / "sweep") + " --maps",
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("usable links |"), std::string::npos) << out;
  const nlohmann::json doc = ReadJson(tmp.path() / "sweep/sweep.json");
  for (const auto& row : doc["rows"]) {
    EXPECT_TRUE(row["usable_links"].is_number()) << row.dump();
    EXPECT_LE(row["usable_links"].get<int>(), row["key_images"].get<int>() - 1);
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "sweep/tau_0.40" / kEvaluationFileName));
  // Without --gt, no such column.
  ASSERT_EQ(RunVmap("sweep " + Quote(Shared() / "data/kitti07") + " --last 19 --thresholds 0.5 -q", &out), 0) << out;
  EXPECT_EQ(out.find("usable links"), std::string::npos) << out;
}

// A map built from a relative path is evaluated from any folder: it records the input's absolute path too.
TEST(EvalCli, AMapBuiltFromARelativePathIsEvaluatedFromAnyFolder) {
  testing::ScopedTempDir tmp;
  testing::WriteKittiSequence(Synthetic(), tmp.path() / "seq");
  fs::create_directory(tmp.path() / "elsewhere");
  std::string out;
  const testing::CliResult built = testing::RunVmap("build seq -q -o map", "cd " + Quote(tmp.path()) + " &&");
  ASSERT_EQ(built.status, 0) << built.output;
  EXPECT_EQ(ReadMap(tmp.path() / "map").input.path, "seq");
  const testing::CliResult evaluated =
      testing::RunVmap("eval ../map --no-table --no-save", "cd " + Quote(tmp.path() / "elsewhere") + " &&");
  EXPECT_EQ(evaluated.status, 0) << evaluated.output;
  EXPECT_NE(evaluated.output.find("usable links"), std::string::npos) << evaluated.output;
  // Found neither from here nor where it was: both said.
  fs::rename(tmp.path() / "seq", tmp.path() / "moved");
  const testing::CliResult moved =
      testing::RunVmap("eval ../map --no-table --no-save", "cd " + Quote(tmp.path() / "elsewhere") + " &&");
  EXPECT_EQ(moved.status, 2) << moved.output;
  EXPECT_NE(moved.output.find("'seq' is not found from here nor at '" + (tmp.path() / "seq").string() + "'"),
            std::string::npos)
      << moved.output;
}

TEST(EvalCli, CameraOptionAndMissingGroundTruthOrIntrinsics) {
  testing::ScopedTempDir tmp;
  const testing::SyntheticSequence sequence = Synthetic();
  testing::WriteImageFolder(sequence, tmp.path() / "frames");
  std::string out;
  // No intrinsics beside the folder: a map without camera and without poses.
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "frames") + " -q -o " + Quote(tmp.path() / "plain"), &out), 0) << out;
  EXPECT_FALSE(ReadMap(tmp.path() / "plain").input.camera);
  EXPECT_EQ(RunVmap("eval " + Quote(tmp.path() / "plain"), &out), 2);
  EXPECT_NE(out.find("--gt"), std::string::npos) << out;
  // An input not found from here (built elsewhere, from a relative path), or none recorded: said so, where the second
  // was "cannot make absolute path (an unexpected error)".
  for (const char* recorded : {"frames_elsewhere", ""}) {
    nlohmann::json doc = ReadJson(tmp.path() / "plain" / kMapFileName);
    doc["input"]["path"] = recorded;
    doc["input"].erase("absolute_path");  // a map of before it was recorded
    std::ofstream(tmp.path() / "plain" / kMapFileName) << doc.dump();
    EXPECT_EQ(RunVmap("eval " + Quote(tmp.path() / "plain"), &out), 2) << out;
    EXPECT_NE(out.find(*recorded ? "'frames_elsewhere' is not found from here" : "the map records no input"),
              std::string::npos)
        << out;
    EXPECT_EQ(out.find("unexpected"), std::string::npos) << out;
  }
  {
    nlohmann::json doc = ReadJson(tmp.path() / "plain" / kMapFileName);
    doc["input"]["path"] = (tmp.path() / "frames").string();
    std::ofstream(tmp.path() / "plain" / kMapFileName) << doc.dump();
  }
  // Ground truth given, intrinsics not: the error says how to give them.
  testing::WriteKittiSequence(sequence, tmp.path() / "kitti");
  const std::string poses = Quote(tmp.path() / "kitti/poses.txt");
  EXPECT_EQ(RunVmap("eval " + Quote(tmp.path() / "plain") + " --gt " + poses, &out), 2);
  EXPECT_NE(out.find("--camera"), std::string::npos) << out;
  // With --camera at eval time, the pose comes from F.
  const cv::Matx33d& K = sequence.K;
  const std::string camera = cv::format("%.6f,%.6f,%.6f,%.6f", K(0, 0), K(1, 1), K(0, 2), K(1, 2));
  ASSERT_EQ(RunVmap("eval " + Quote(tmp.path() / "plain") + " --gt " + poses + " --camera " + camera +
                        " --no-table --json " + Quote(tmp.path() / "e.json"),
                    &out),
            0)
      << out;
  EXPECT_EQ(ReadJson(tmp.path() / "e.json")["links"][0]["pose_source"], "fundamental");
  EXPECT_EQ(ReadJson(tmp.path() / "e.json")["ground_truth"]["format"], "kitti");

  // An OpenCV calibration file as --camera at build time: the map carries the camera and poses.
  {
    cv::FileStorage fs((tmp.path() / "camera.yaml").string(), cv::FileStorage::WRITE);
    fs << "image_width" << 320 << "image_height" << 240 << "camera_matrix" << cv::Mat(K) << "distortion_coefficients"
       << cv::Mat::zeros(5, 1, CV_64F);
  }
  ASSERT_EQ(RunVmap("build " + Quote(tmp.path() / "frames") + " -q --camera " + Quote(tmp.path() / "camera.yaml") +
                        " -o " + Quote(tmp.path() / "posed"),
                    &out),
            0)
      << out;
  const VisualMap posed = ReadMap(tmp.path() / "posed");
  ASSERT_TRUE(posed.input.camera);
  EXPECT_EQ(posed.input.camera->K(), K);
  EXPECT_TRUE(posed.links.front().has_pose);
  const auto options = nlohmann::json::parse(posed.options_json);
  EXPECT_EQ(options["pose"]["method"], "essential");
  EXPECT_EQ(options["source"]["camera"], (tmp.path() / "camera.yaml").string());

  // Bad values are refused with the option's name.
  EXPECT_EQ(RunVmap("build " + Quote(tmp.path() / "frames") + " -q --camera 1,2,3 -o " + Quote(tmp.path() / "x"), &out),
            2);
  EXPECT_NE(out.find("--camera"), std::string::npos) << out;
  EXPECT_EQ(RunVmap("build " + Quote(tmp.path() / "frames") + " -q --pose magic -o " + Quote(tmp.path() / "x"), &out),
            2);
  EXPECT_NE(out.find("pose method"), std::string::npos) << out;
  EXPECT_EQ(RunVmap("eval " + Quote(tmp.path() / "posed") + " --gt " + poses + " --min-parallax -3", &out), 2);
  EXPECT_NE(out.find("--min-parallax"), std::string::npos) << out;
  std::ofstream(tmp.path() / "junk.txt") << "hello world\n";
  EXPECT_EQ(RunVmap("eval " + Quote(tmp.path() / "posed") + " --gt " + Quote(tmp.path() / "junk.txt"), &out), 2);
  EXPECT_NE(out.find("--gt-format"), std::string::npos) << out;
  // A format without the file it describes would be ignored: the input's own ground truth has its own.
  EXPECT_EQ(RunVmap("eval " + Quote(tmp.path() / "posed") + " --gt-format tum", &out), 2);
  EXPECT_NE(out.find("--gt-format needs --gt"), std::string::npos) << out;
}

}  // namespace vmap
