// `vmap eval` against synthetic sequences with known camera motion, written in each dataset layout: every
// convention (pose direction, image order, camera-to-world, source index, timestamps, resizing, EuRoC's
// body frame) is exercised, and getting any of them wrong must make a test fail.

#include "vmap/evaluation/map_evaluation.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"
#include "vmap/core/options_json.h"
#include "vmap/evaluation/evaluation_inputs.h"
#include "vmap/evaluation/evaluation_json.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/report/evaluation_summary.h"
#include "vmap/sources/kitti_frame_number.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// Turning while moving sideways and forward: rotations do not commute with a wrong convention.
const testing::SyntheticSequence& Sequence() {
  static const testing::SyntheticSequence sequence = [] {
    testing::SyntheticOptions options;
    options.num_frames = 40;
    options.step = 0.06;
    options.yaw_per_frame = 0.01;
    return testing::RenderSyntheticSequence(options);
  }();
  return sequence;
}

VisualMap Build(const std::string& input, FrameSourceOptions source_options = {}, double tau = 0.6) {
  MapBuilderOptions options;
  options.key_images.tau = tau;
  options.show_progress = false;
  options.verifier.threshold = 1.0;
  const auto matcher = CreateOrbMatcher({});
  auto source = OpenFrameSource(input, source_options);
  return BuildMap(*source, *matcher, options);
}

// One map of the KITTI-layout sequence, built once for the tests that only read it.
struct KittiFixture {
  testing::ScopedTempDir tmp;
  fs::path sequence;
  VisualMap map;
  GroundTruth truth;
  KittiFixture() {
    sequence = tmp.path() / "kitti";
    testing::WriteKittiSequence(Sequence(), sequence);
    map = Build(sequence.string());
    truth = ReadGroundTruth((sequence / "poses.txt").string());
  }
};

const KittiFixture& Kitti() {
  static const KittiFixture fixture;
  return fixture;
}

void ExpectAllUsable(const MapEvaluation& e, double max_rotation_deg = 1.0) {
  SCOPED_TRACE(FormatEvaluationTable(e));
  EXPECT_GE(e.summary.links, 3);
  EXPECT_EQ(e.summary.evaluated_links, e.summary.links);
  EXPECT_EQ(e.summary.usable_links, e.summary.links);
  EXPECT_LT(e.summary.rotation_error_deg_median, max_rotation_deg);
  for (const LinkEvaluation& l : e.links) {
    EXPECT_TRUE(l.usable) << "link " << l.link << " rotation " << l.rotation_error_deg << " translation "
                          << l.translation_error_deg << " parallax " << l.true_parallax_px;
    // The verified matches lie on the true epipolar lines: the true F has the images in the right order.
    EXPECT_GT(l.verified_within, 0.9) << "link " << l.link;
    EXPECT_LT(l.verified_sampson_median, 1.0) << "link " << l.link;
  }
}

}  // namespace

TEST(MapEvaluation, SyntheticKittiSequenceHasOnlyUsableLinks) {
  const KittiFixture& k = Kitti();
  ASSERT_TRUE(k.map.input.camera);
  EXPECT_EQ(k.map.input.camera->K(), Sequence().K);
  for (const Link& link : k.map.links) {
    EXPECT_TRUE(link.has_pose);
    EXPECT_GT(link.parallax, 1.0);
    EXPECT_FALSE(link.planar);
  }
  const MapEvaluation e = EvaluateMap(k.map, k.truth, *k.map.input.camera, EvaluationOptions());
  ExpectAllUsable(e);
  EXPECT_EQ(e.links[0].pose_source, "stored");
  // The true motion between the key images is what the sequence was rendered with.
  const LinkEvaluation& first = e.links[0];
  EXPECT_NEAR(first.true_rotation_deg, 0.01 * (first.to_source - first.from_source) * 180 / CV_PI, 1e-6);
  EXPECT_GT(e.summary.translation_error_deg_median, 0.0);
  EXPECT_LT(e.summary.translation_error_deg_median, 5.0);
}

TEST(MapEvaluation, PosesDoNotDependOnTheNumberOfThreads) {
  VisualMap again = Kitti().map;
  AnalyzeLinks(again, LinkAnalysisOptions(), 1);
  const VisualMap& built = Kitti().map;  // analysed on every core
  ASSERT_EQ(again.links.size(), built.links.size());
  for (size_t i = 0; i < again.links.size(); ++i) {
    EXPECT_EQ(again.links[i].R, built.links[i].R);
    EXPECT_EQ(again.links[i].t, built.links[i].t);
    EXPECT_EQ(again.links[i].parallax, built.links[i].parallax);
    EXPECT_EQ(again.links[i].homography_share, built.links[i].homography_share);
  }
}

TEST(MapEvaluation, PoseFromFundamentalWhenTheMapHasNone) {
  VisualMap map = Kitti().map;
  for (Link& link : map.links) link.has_pose = false;
  const MapEvaluation e = EvaluateMap(map, Kitti().truth, *map.input.camera, EvaluationOptions());
  // F has two degrees of freedom more than E: K^T F K is further from the true motion than E is.
  ExpectAllUsable(e, 3.0);
  EXPECT_EQ(e.links[0].pose_source, "fundamental");
}

// Each convention turned the wrong way must make links unusable.
TEST(MapEvaluation, WrongConventionsAreCaught) {
  const KittiFixture& k = Kitti();
  const Camera& camera = *k.map.input.camera;
  const auto usable_share = [&](const VisualMap& map, const GroundTruth& truth) {
    const MapEvaluation e = EvaluateMap(map, truth, camera, EvaluationOptions());
    return static_cast<double>(e.summary.usable_links) / e.summary.links;
  };
  ASSERT_EQ(usable_share(k.map, k.truth), 1.0);

  // Ground truth read as world-to-camera instead of camera-to-world.
  GroundTruth inverted = k.truth;
  for (cv::Matx44d& T : inverted.camera_to_world) T = T.inv();
  EXPECT_LT(usable_share(k.map, inverted), 0.5);

  // The pose stored the other way round (X_from = R X_to + t).
  VisualMap reversed = k.map;
  for (Link& link : reversed.links) {
    const cv::Matx33d R = link.R.t();
    link.t = -(R * link.t);
    link.R = R;
  }
  EXPECT_LT(usable_share(reversed, k.truth), 0.5);

  // The translation's sign flipped (cheirality ignored).
  VisualMap flipped = k.map;
  for (Link& link : flipped.links) link.t = -link.t;
  const MapEvaluation flipped_eval = EvaluateMap(flipped, k.truth, camera, EvaluationOptions());
  for (const LinkEvaluation& l : flipped_eval.links) EXPECT_GT(l.translation_error_deg, 150.0);

  // The two images of each link swapped (F transposed to fit them): the pose of F is then the inverse motion.
  VisualMap swapped = k.map;
  for (Link& link : swapped.links) {
    for (Correspondence& c : link.correspondences) std::swap(c.p0, c.p1);
    link.has_pose = false;
    link.F = link.F.t();
  }
  EXPECT_LT(usable_share(swapped, k.truth), 0.5);
}

TEST(MapEvaluation, FirstAndStrideTieKeyImagesToTheirSourceIndex) {
  FrameSourceOptions source;
  source.first = 3;
  source.stride = 2;
  const VisualMap map = Build(Kitti().sequence.string(), source, 0.7);
  ASSERT_GE(map.key_images.size(), 4u);
  EXPECT_EQ(map.key_images[0].source_index, 3);
  EXPECT_EQ(map.key_images[1].source_index, 3 + 2 * map.key_images[1].frame_index);
  const MapEvaluation right = EvaluateMap(map, Kitti().truth, *map.input.camera, EvaluationOptions());
  ExpectAllUsable(right);
  // Tied by frame index instead, the true motion would be half the real one: the rotations no longer agree. (A
  // KITTI key image is tied by the number of its file, which is its source index here; without a number in the
  // name, by its source index.)
  VisualMap by_frame = map;
  for (KeyImage& key : by_frame.key_images) {
    EXPECT_EQ(KittiFrameNumber(key.source_name), key.source_index) << key.source_name;
    key.source_name = "frame.png";
    key.source_index = key.frame_index;
  }
  const MapEvaluation wrong = EvaluateMap(by_frame, Kitti().truth, *map.input.camera, EvaluationOptions());
  EXPECT_GT(wrong.summary.rotation_error_deg_median, 4 * right.summary.rotation_error_deg_median);
  EXPECT_GT(wrong.summary.rotation_error_deg_median, 1.0);
}

TEST(MapEvaluation, ResizedMapsUseTheScaledCamera) {
  FrameSourceOptions source;
  source.resize = "240";  // 320x240 -> 240x180
  const VisualMap map = Build(Kitti().sequence.string(), source, 0.5);
  ASSERT_TRUE(map.input.camera);
  EXPECT_EQ(map.input.camera->size, cv::Size(240, 180));
  EXPECT_NEAR(map.input.camera->fx, Sequence().K(0, 0) * 0.75, 1e-9);
  const MapEvaluation e = EvaluateMap(map, Kitti().truth, *map.input.camera, EvaluationOptions());
  ExpectAllUsable(e);
  // Poses estimated with the native camera on the resized key images would be wrong: rotations scale with
  // 1 / f.
  VisualMap unscaled = map;
  unscaled.input.camera = *Kitti().map.input.camera;
  AnalyzeLinks(unscaled, LinkAnalysisOptions());
  const MapEvaluation wrong = EvaluateMap(unscaled, Kitti().truth, *map.input.camera, EvaluationOptions());
  const auto total_rotation_error = [](const MapEvaluation& evaluation) {
    double sum = 0;
    for (const LinkEvaluation& l : evaluation.links) sum += l.rotation_error_deg;
    return sum;
  };
  EXPECT_GT(total_rotation_error(wrong), 2 * total_rotation_error(e)) << FormatEvaluationTable(wrong);
  // EvaluationCamera scales the input's own intrinsics when the map has no camera.
  VisualMap without = map;
  without.input.camera.reset();
  EXPECT_NEAR(EvaluationCamera(without, "").fx, map.input.camera->fx, 1e-9);
}

TEST(MapEvaluation, TumSequenceIsAssociatedByTimestamp) {
  testing::ScopedTempDir tmp;
  // Ground truth sampled 5 ms after each frame, as a motion-capture system would.
  testing::WriteTumSequence(Sequence(), tmp.path() / "tum", 1.0 / 30, 0.005);
  const VisualMap map = Build((tmp.path() / "tum").string());
  ASSERT_TRUE(map.input.camera);
  const GroundTruth truth = MapGroundTruth(map, "", GroundTruthFormat::kAuto);
  EXPECT_EQ(truth.format, GroundTruthFormat::kTum);
  ExpectAllUsable(EvaluateMap(map, truth, *map.input.camera, EvaluationOptions()));
  // With a tolerance below the 5 ms offset no key image has a pose.
  EvaluationOptions strict;
  strict.max_time_difference = 0.001;
  EXPECT_EQ(EvaluateMap(map, truth, *map.input.camera, strict).summary.evaluated_links, 0);
}

TEST(MapEvaluation, EurocBodyPosesAreTurnedIntoCameraPoses) {
  testing::ScopedTempDir tmp;
  // The camera looks along the body's x axis, 10 cm in front of it, as on a drone.
  cv::Matx44d body_to_camera(0, 0, 1, 0.10,    //
                             -1, 0, 0, 0.02,   //
                             0, -1, 0, -0.03,  //
                             0, 0, 0, 1);
  testing::WriteEurocSequence(Sequence(), tmp.path() / "euroc", body_to_camera);
  const VisualMap map = Build((tmp.path() / "euroc").string());
  ASSERT_TRUE(map.input.camera);
  const GroundTruth truth = MapGroundTruth(map, "", GroundTruthFormat::kAuto);
  EXPECT_EQ(truth.format, GroundTruthFormat::kEuroc);
  ExpectAllUsable(EvaluateMap(map, truth, *map.input.camera, EvaluationOptions()));
  // Without T_BS the body's motion is not the camera's.
  const std::string file = (tmp.path() / "euroc/mav0/state_groundtruth_estimate0/data.csv").string();
  const GroundTruth body = ReadGroundTruth(file, GroundTruthFormat::kEuroc);
  EXPECT_LT(EvaluateMap(map, body, *map.input.camera, EvaluationOptions()).summary.verified_within_mean, 0.5);
  // The same file given as --gt: its cam0/sensor.yaml beside it says where the camera sits (it was taken as the
  // body's poses, and the links looked bad).
  ExpectAllUsable(
      EvaluateMap(map, MapGroundTruth(map, file, GroundTruthFormat::kAuto), *map.input.camera, EvaluationOptions()));
  // A copy elsewhere: the map's input (an EuRoC sequence) says it.
  fs::copy_file(file, tmp.path() / "euroc_poses.csv");
  ExpectAllUsable(EvaluateMap(map,
                              MapGroundTruth(map, (tmp.path() / "euroc_poses.csv").string(), GroundTruthFormat::kEuroc),
                              *map.input.camera, EvaluationOptions()));
}

TEST(MapEvaluation, OptionsAreCheckedAndTheDocumentRoundTrips) {
  EvaluationOptions bad;
  bad.max_rotation_error_deg = 0;
  EXPECT_EQ(testing::OptionErrorPath([&] { bad.Check(); }), "max_rotation_error_deg");
  bad = EvaluationOptions();
  bad.min_parallax_px = -1;
  EXPECT_EQ(testing::OptionErrorPath([&] { bad.Check(); }), "min_parallax_px");

  const KittiFixture& k = Kitti();
  MapEvaluation e = EvaluateMap(k.map, k.truth, *k.map.input.camera, EvaluationOptions());
  e.map_path = "map";
  testing::ScopedTempDir tmp;
  const fs::path file = tmp.path() / kEvaluationFileName;
  std::ofstream(file) << EvaluationToJson(e);
  const MapEvaluation back = ReadEvaluation(file.string());
  ASSERT_EQ(back.links.size(), e.links.size());
  EXPECT_EQ(back.summary.usable_links, e.summary.usable_links);
  EXPECT_EQ(back.summary.strict_usable_links, e.summary.strict_usable_links);
  EXPECT_EQ(back.summary.unflagged_links, e.summary.unflagged_links);
  EXPECT_EQ(back.links[1].translation_known, e.links[1].translation_known);
  EXPECT_EQ(back.links[1].consistent_matches, e.links[1].consistent_matches);
  EXPECT_DOUBLE_EQ(back.summary.rotation_error_deg_median, e.summary.rotation_error_deg_median);
  EXPECT_DOUBLE_EQ(back.links[1].translation_error_deg, e.links[1].translation_error_deg);
  EXPECT_EQ(back.links[1].to_frame, e.links[1].to_frame);
  EXPECT_EQ(back.camera.K(), e.camera.K());
  std::ofstream(file) << "{\"format\": \"something else\"}";
  EXPECT_THROW(ReadEvaluation(file.string()), InputError);
}

TEST(MapEvaluation, OptionsReadBackAsWrittenAndKeepTheDefaultsOfWhatIsNotRecorded) {
  EvaluationOptions written;
  written.max_rotation_error_deg = 2.5;
  written.max_translation_error_deg = 15.0;
  written.min_parallax_px = 4.0;
  written.sampson_threshold_px = 1.5;
  written.max_time_difference = 0.05;
  EvaluationOptions read;
  OptionsFromJson(JsonFieldReader(OptionsToJson(written), "options"), &read);
  EXPECT_EQ(OptionsToJson(read), OptionsToJson(written));
  EXPECT_EQ(read.max_time_difference, 0.05);
  EvaluationOptions partly;
  OptionsFromJson(JsonFieldReader(nlohmann::json{{"min_parallax_px", 3.0}}, "options"), &partly);
  EXPECT_EQ(partly.min_parallax_px, 3.0);
  EXPECT_EQ(partly.max_rotation_error_deg, EvaluationOptions().max_rotation_error_deg);
  EXPECT_THROW(OptionsFromJson(JsonFieldReader(nlohmann::json{{"min_parallax_px", "3"}}, "options"), &partly),
               InputError);
}

// Frames shown twice in a row (7-Scenes repeats a frame when one was dropped) are never promoted to key
// images when another frame will do; with the check off, some links join two views of one viewpoint.
TEST(MapEvaluation, RepeatedFramesAreNotChosenAsKeyImages) {
  testing::ScopedTempDir tmp;
  testing::SyntheticSequence doubled = Sequence();
  doubled.frames.clear();
  doubled.poses.clear();
  for (size_t i = 0; i < Sequence().frames.size(); i += 2) {
    for (int copy = 0; copy < 2; ++copy) {
      doubled.frames.push_back(Sequence().frames[i]);
      doubled.poses.push_back(Sequence().poses[i]);
    }
  }
  testing::WriteKittiSequence(doubled, tmp.path() / "doubled");
  const auto links_without_parallax = [](const VisualMap& map) {
    int count = 0;
    for (const Link& link : map.links) count += link.has_fundamental && link.parallax < 0.5 ? 1 : 0;
    return count;
  };
  MapBuilderOptions options;
  options.key_images.tau = 0.95;
  options.show_progress = false;
  options.verifier.threshold = 1.0;
  const auto matcher = CreateOrbMatcher({});
  auto source = OpenFrameSource((tmp.path() / "doubled").string());
  const VisualMap avoided = BuildMap(*source, *matcher, options);
  options.key_images.min_key_displacement = 0.0;
  source = OpenFrameSource((tmp.path() / "doubled").string());
  const VisualMap published = BuildMap(*source, *matcher, options);
  EXPECT_GT(links_without_parallax(published), 0) << "the scenario must produce degenerate links";
  EXPECT_EQ(links_without_parallax(avoided), 0);
  for (const Link& link : published.links) {
    if (link.has_fundamental && link.parallax < 0.5) {
      EXPECT_TRUE(link.planar);  // H = I explains it all
    }
  }
}

}  // namespace vmap

namespace vmap {

// The parallax that decides whether a translation is judged comes from the matches that agree with the ground
// truth, so a link cannot exempt itself with wrong inliers; the summary counts the map's own flags.
TEST(MapEvaluation, ParallaxFromMatchesThatAgreeWithTheTruthAndTheMapsFlagsCounted) {
  const KittiFixture& k = Kitti();
  const Camera& camera = *k.map.input.camera;
  const MapEvaluation honest = EvaluateMap(k.map, k.truth, camera, EvaluationOptions());
  ASSERT_EQ(honest.summary.strict_usable_links, honest.summary.links);
  ASSERT_EQ(honest.summary.unflagged_links + honest.summary.flagged_links, honest.summary.links);

  // Link 0's verified matches replaced by wrong ones with little parallax: each 6 px off its true epipolar
  // line, beside where the rotation alone would take it. By its own inliers the link would have 6 px of
  // parallax and its translation would not be judged; the true matches (kept, as rejected ones) have more.
  VisualMap corrupted = k.map;
  Link& link = corrupted.links[0];
  ASSERT_GT(honest.links[0].true_parallax_px, 10.0);
  cv::Matx33d R_true;
  cv::Vec3d t_true;
  RelativeFromCameraToWorld(*KeyImagePose(k.truth, k.map.key_images[link.from_key], 0.02),
                            *KeyImagePose(k.truth, k.map.key_images[link.to_key], 0.02), &R_true, &t_true);
  const cv::Matx33d K = camera.K();
  const cv::Matx33d F_true = FundamentalFromPose(R_true, t_true, K);
  const std::vector<Correspondence> original = link.correspondences;
  for (int i = 0; i < link.num_verified; ++i) {
    const cv::Point2f p0 = link.correspondences[i].p0;
    const cv::Vec3d rotated = K * R_true * K.inv() * cv::Vec3d(p0.x, p0.y, 1.0);
    const cv::Vec3d line = F_true * cv::Vec3d(p0.x, p0.y, 1.0);
    const double norm = std::hypot(line[0], line[1]);
    link.correspondences[i].p1 = cv::Point2f(static_cast<float>(rotated[0] / rotated[2] + 6.0 * line[0] / norm),
                                             static_cast<float>(rotated[1] / rotated[2] + 6.0 * line[1] / norm));
  }
  link.correspondences.insert(link.correspondences.end(), original.begin(), original.begin() + link.num_verified);
  const MapEvaluation e = EvaluateMap(corrupted, k.truth, camera, EvaluationOptions());
  EXPECT_NEAR(e.links[0].true_parallax_px, honest.links[0].true_parallax_px, 0.05 * honest.links[0].true_parallax_px);
  EXPECT_GE(e.links[0].consistent_matches, link.num_verified / 2);
  EXPECT_LE(e.links[0].consistent_matches, honest.links[0].consistent_matches + 2) << "the wrong ones left out";

  // Two translations reversed, one of them flagged by the map: the flagged one counts as flagged and wrong,
  // the other as an unflagged link pointing backwards.
  VisualMap reversed = k.map;
  reversed.links[0].t = -reversed.links[0].t;
  reversed.links[0].translation_known = false;
  reversed.links[1].t = -reversed.links[1].t;
  reversed.links[1].translation_known = true;
  const MapEvaluation r = EvaluateMap(reversed, k.truth, camera, EvaluationOptions());
  EXPECT_EQ(r.summary.flagged_links, honest.summary.flagged_links + (k.map.links[0].translation_known ? 1 : 0) -
                                         (k.map.links[1].translation_known ? 0 : 1));
  EXPECT_GE(r.summary.flagged_wrong_links, 1);
  EXPECT_EQ(r.summary.unflagged_reversed_links, 1);
  EXPECT_EQ(r.summary.strict_usable_links, honest.summary.strict_usable_links - 2);
  EXPECT_LT(r.summary.unflagged_right_share, 1.0);
}

// The true pose against the stored one on the link's own matches: on an honest synthetic map the stored pose
// is the better fit only by the rendering's noise (a near-zero excess, as on KITTI); a stored rotation turned
// by 3 degrees makes the truth the far better fit (a large negative excess).
TEST(MapEvaluation, TruePoseCostExcessSaysWhetherTheMatchesAgreeWithTheTruth) {
  const KittiFixture& k = Kitti();
  const Camera& camera = *k.map.input.camera;
  const MapEvaluation honest = EvaluateMap(k.map, k.truth, camera, EvaluationOptions());
  ASSERT_TRUE(std::isfinite(honest.links[0].true_pose_cost_excess));
  EXPECT_LT(std::abs(honest.summary.true_pose_cost_excess_median), 10.0);
  VisualMap turned = k.map;
  cv::Matx33d turn;
  cv::Rodrigues(cv::Vec3d(0.0, 3.0 * CV_PI / 180.0, 0.0), turn);
  turned.links[0].R = turn * turned.links[0].R;
  const MapEvaluation e = EvaluateMap(turned, k.truth, camera, EvaluationOptions());
  EXPECT_LT(e.links[0].true_pose_cost_excess, honest.links[0].true_pose_cost_excess - 20.0);
  EXPECT_DOUBLE_EQ(e.links[1].true_pose_cost_excess, honest.links[1].true_pose_cost_excess);
}

}  // namespace vmap
