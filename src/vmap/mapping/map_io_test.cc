#include "vmap/mapping/map_io.h"

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

VisualMap SmallMap(const fs::path& directory) {
  VisualMap map;
  map.input.path = "video.mp4";
  map.input.format = SourceFormat::kVideo;
  map.input.frame_size = {64, 48};
  map.options_json = R"({"tau": 0.5, "quality_mean": "arithmetic"})";
  map.num_frames = 20;
  fs::create_directories(directory / "keys");
  for (int f : {0, 9, 19}) {
    KeyImage k;
    k.frame_index = f;
    k.source_index = f;
    k.timestamp = f / 30.0;
    k.source_name = "frame_" + std::to_string(f);
    k.image_file = "keys/" + std::to_string(f) + ".png";
    cv::imwrite((directory / k.image_file).string(), cv::Mat(48, 64, CV_8U, cv::Scalar(f)));
    map.key_images.push_back(k);
  }
  for (int i = 0; i < 2; ++i) {
    Link l;
    l.from_key = i;
    l.to_key = i + 1;
    l.num_tentative = 3;
    l.num_verified = 2;
    l.similarity = 2.0 / 3.0;
    l.has_fundamental = true;
    l.F = cv::Matx33d(0, -1e-3, 0.1 * i, 1e-3, 0, -0.2, -0.1, 0.2, 1);
    for (int c = 0; c < 3; ++c) l.correspondences.push_back({{1.5f * c, 2.f + i}, {3.25f * c, 4.f}});
    map.links.push_back(l);
  }
  map.evaluations = {{0, 1, 0.9, 10, 9, true}, {0, 2, 0.0, 3, 0, false}};
  map.quality = 0.42;
  return map;
}

void WriteText(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

std::string ErrorOf(const fs::path& directory) {
  try {
    ReadMap(directory);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(MapIo, RoundTripKeepsEverything) {
  testing::TempDir tmp;
  const VisualMap map = SmallMap(tmp.path());
  WriteMapFiles(map, tmp.path());
  const VisualMap back = ReadMap(tmp.path());
  ASSERT_EQ(back.key_images.size(), 3u);
  EXPECT_EQ(back.key_images[1].frame_index, 9);
  EXPECT_NEAR(back.key_images[1].timestamp, 0.3, 1e-12);
  ASSERT_EQ(back.links.size(), 2u);
  EXPECT_EQ(back.links[1].correspondences.size(), 3u);
  EXPECT_EQ(back.links[1].correspondences[2].p1.x, 6.5f);
  EXPECT_EQ(back.links[1].correspondences[0].p0.y, 3.f);
  EXPECT_EQ(back.links[1].F(0, 2), 0.1);
  EXPECT_EQ(back.evaluations.size(), 2u);
  EXPECT_FALSE(back.evaluations[1].matched);
  EXPECT_EQ(back.num_frames, 20);
  EXPECT_DOUBLE_EQ(back.quality, 0.42);
  // Correspondences are 16 bytes each, as documented.
  EXPECT_EQ(fs::file_size(tmp.path() / kCorrespondencesFileName), 6u * 16u);
}

TEST(MapIo, MissingOrMalformedMapsNameTheProblem) {
  testing::TempDir tmp;
  EXPECT_NE(ErrorOf(tmp.path() / "nope").find("does not exist"), std::string::npos);
  EXPECT_NE(ErrorOf(tmp.path()).find("map.json is missing"), std::string::npos);

  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  fs::remove(tmp.path() / "keys/9.png");
  EXPECT_NE(ErrorOf(tmp.path()).find("keys/9.png' is missing"), std::string::npos) << ErrorOf(tmp.path());

  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  fs::remove(tmp.path() / kCorrespondencesFileName);
  EXPECT_NE(ErrorOf(tmp.path()).find("correspondences.bin is missing"), std::string::npos);

  WriteText(tmp.path() / kMapFileName, "{not json");
  EXPECT_NE(ErrorOf(tmp.path()).find("not valid JSON"), std::string::npos);
}

TEST(MapIo, KeyImagePathsCannotLeaveTheMapDirectory) {
  testing::TempDir tmp;
  const fs::path map_dir = tmp.path() / "map";
  VisualMap map = SmallMap(map_dir);
  cv::imwrite((tmp.path() / "outside.png").string(), cv::Mat(4, 4, CV_8U));
  for (const std::string& bad : std::vector<std::string>{"../outside.png", (tmp.path() / "outside.png").string()}) {
    map.key_images[0].image_file = bad;
    WriteMapFiles(map, map_dir);
    EXPECT_NE(ErrorOf(map_dir).find("points outside the map directory"), std::string::npos) << bad;
  }
}

TEST(MapIo, CorrespondenceRangesAreChecked) {
  testing::TempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  doc["links"][1]["correspondences"]["count"] = 1000;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("exceed"), std::string::npos);
}

TEST(MapIo, CameraAndLinkGeometryRoundTrip) {
  testing::TempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  Camera camera = Camera::Make(50.5, 51.0, 31.5, 23.5, {-0.1, 0.01, 0.001, -0.002}, {64, 48});
  camera.origin = "intrinsics.txt";
  map.input.camera = camera;
  Link& link = map.links[1];
  link.below_tau = true;
  link.has_pose = true;
  cv::Rodrigues(cv::Vec3d(0.01, -0.2, 0.03), link.R);
  link.t = cv::normalize(cv::Vec3d(0.3, -0.1, -0.9));
  link.pose_inliers = 2;
  link.parallax = 12.25;
  link.parallax_without_rotation = true;
  link.homography_share = 0.5;
  link.planar = false;
  WriteMapFiles(map, tmp.path());
  const VisualMap back = ReadMap(tmp.path());
  ASSERT_TRUE(back.input.camera);
  EXPECT_EQ(back.input.camera->model, CameraModel::kOpenCV);
  EXPECT_EQ(back.input.camera->K(), camera.K());
  EXPECT_EQ(back.input.camera->distortion(), camera.distortion());
  EXPECT_EQ(back.input.camera->size, cv::Size(64, 48));
  EXPECT_EQ(back.input.camera->origin, "intrinsics.txt");
  EXPECT_FALSE(back.links[0].below_tau);
  EXPECT_FALSE(back.links[0].has_pose);
  EXPECT_LT(back.links[0].parallax, 0);  // not computed
  const Link& l = back.links[1];
  EXPECT_TRUE(l.below_tau);
  ASSERT_TRUE(l.has_pose);
  EXPECT_LT(cv::norm(l.R - link.R), 1e-12);
  EXPECT_LT(cv::norm(l.t - link.t), 1e-12);
  EXPECT_EQ(l.pose_inliers, 2);
  EXPECT_DOUBLE_EQ(l.parallax, 12.25);
  EXPECT_TRUE(l.parallax_without_rotation);
  EXPECT_DOUBLE_EQ(l.homography_share, 0.5);
  // The document says what the numbers mean, and the COLMAP model name.
  std::ifstream in(tmp.path() / kMapFileName);
  const auto doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc["schema_version"], 2);
  EXPECT_EQ(doc["input"]["camera"]["model"], "OPENCV");
  EXPECT_EQ(doc["input"]["camera"]["params"].size(), 8u);
  EXPECT_NE(doc["conventions"]["pose"].get<std::string>().find("X_to = R X_from + t"), std::string::npos);
  EXPECT_FALSE(doc["links"][0].contains("broken"));
}

TEST(MapIo, ReadsSchemaVersionOneMapsWithBrokenLinks) {
  testing::TempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  // A map as vmap wrote it before links had a geometry: `broken`, no camera, no pose.
  doc["schema_version"] = 1;
  doc["input"].erase("camera");
  doc.erase("conventions");
  for (auto& link : doc["links"]) {
    for (const char* key : {"below_tau", "pose", "parallax_px", "parallax_rotation_removed", "homography_share",
                            "planar"}) {
      link.erase(key);
    }
  }
  doc["links"][0]["broken"] = true;
  doc["links"][1]["broken"] = false;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  const VisualMap map = ReadMap(tmp.path());
  EXPECT_TRUE(map.links[0].below_tau);
  EXPECT_FALSE(map.links[1].below_tau);
  EXPECT_FALSE(map.links[0].has_pose);
  EXPECT_FALSE(map.input.camera);
}

TEST(MapIo, MalformedGeometryIsRefused) {
  testing::TempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  const auto original = nlohmann::json::parse(in);
  auto doc = original;
  doc["links"][0]["pose"] = {{"R", {2, 0, 0, 0, 1, 0, 0, 0, 1}}, {"t", {0, 0, 1}}, {"inliers", 3}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("not a rotation matrix"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["links"][0]["pose"] = {{"R", {1, 0, 0, 0, 1, 0, 0, 0, 1}}, {"t", {0, 0, 3}}, {"inliers", 3}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("not a unit vector"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["input"]["camera"] = {{"model", "PINHOLE"}, {"params", {500, 500, 320}}, {"width", 64}, {"height", 48}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("input.camera"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["links"][0]["parallax_px"] = "far";
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("parallax_px"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["links"][1]["planar"] = "yes";
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("links[1]"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["input"]["camera"] = {{"model", "PINHOLE"}, {"params", {500, 500, 32, 24}}, {"width", "wide"}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("input.camera"), std::string::npos) << ErrorOf(tmp.path());
}

}  // namespace vmap
