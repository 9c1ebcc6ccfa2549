// A map written and read back (ReadMap, WriteMapFiles, WriteMapJson): every field kept, maps of older schemas read,
// key images read and their sizes from their headers, and what makes a folder a vmap map.
#include "vmap/map/map_io.h"

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE

#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/map_io_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::ReadMapError;
using testing::SmallMap;
using testing::WriteText;

TEST(MapIo, RoundTripKeepsEverything) {
  testing::ScopedTempDir tmp;
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

// A run writing snapshots replaces the map's folder whole (a rename exchange with a new folder) while readers read
// it: each read gets one snapshot or the next, whole, never a mix (whose files disagree: it used to be called
// malformed). As the writer does, every snapshot is a new folder; they alternate between two maps.
TEST(MapIo, AReaderOfAMapReplacedWhileItReadsGetsOneMapOrTheOther) {
  testing::ScopedTempDir tmp;
  const fs::path read_here = tmp.path() / "map";
  const auto write_snapshot = [](const fs::path& folder, bool longer) {
    VisualMap map = SmallMap(folder);
    if (longer) {
      for (Link& link : map.links) link.correspondences.insert(link.correspondences.end(), 3, {{1, 2}, {3, 4}});
    }
    WriteMapFiles(map, folder);
  };
  write_snapshot(read_here, false);
  std::atomic<bool> done{false};
  std::atomic<int> snapshots{0};
  std::thread writer([&] {
    for (int k = 1; !done && k < 5000; ++k) {
      const fs::path next = tmp.path() / ("snapshot" + std::to_string(k));
      write_snapshot(next, k % 2 == 1);
      ASSERT_EQ(renameat2(AT_FDCWD, next.c_str(), AT_FDCWD, read_here.c_str(), RENAME_EXCHANGE), 0);
      ++snapshots;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  int reads[2] = {0, 0};
  std::string failure;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (failure.empty() && (snapshots < 50 || reads[0] + reads[1] < 300) &&
         std::chrono::steady_clock::now() < deadline) {
    try {
      const VisualMap map = ReadMap(read_here);
      ++reads[map.links.at(0).correspondences.size() == 3 ? 0 : 1];
      for (const Link& link : map.links) {
        if (link.correspondences.size() != map.links[0].correspondences.size()) failure = "a mix of the two maps";
      }
    } catch (const InputError& e) {
      failure = e.what();
    }
  }
  done = true;
  writer.join();
  EXPECT_EQ(failure, "");
  EXPECT_GE(snapshots, 50);
  EXPECT_GT(reads[0], 0);
  EXPECT_GT(reads[1], 0);
}

TEST(MapIo, ReadKeyImageDecodesTheKeyImagesReadMapChecked) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  const VisualMap map = ReadMap(tmp.path());
  const cv::Mat color = ReadKeyImage(tmp.path(), map.key_images[1]);
  EXPECT_EQ(color.type(), CV_8UC3);
  EXPECT_EQ(color.size(), cv::Size(64, 48));
  const cv::Mat gray = ReadKeyImage(tmp.path(), map.key_images[1], /*grayscale=*/true);
  ASSERT_EQ(gray.type(), CV_8UC1);
  EXPECT_EQ(gray.at<uchar>(10, 10), 9) << "key image of frame 9 is filled with 9";

  // The map changed on disk after ReadMap: each problem is named with its file and the fix.
  auto ErrorOf = [](const auto& read) -> std::string {
    try {
      read();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  KeyImage escaping = map.key_images[0];
  escaping.image_file = "../outside.png";
  EXPECT_NE(ErrorOf([&] { ReadKeyImage(tmp.path(), escaping); }).find("points outside the map directory"),
            std::string::npos);
  // Replaced by an image of another size: refused by its header when the map's frame size is given.
  cv::imwrite((tmp.path() / "keys/9.png").string(), cv::Mat(24, 32, CV_8UC1, cv::Scalar(9)));
  EXPECT_EQ(ReadKeyImage(tmp.path(), map.key_images[1]).size(), cv::Size(32, 24));
  const std::string resized = ErrorOf([&] { ReadKeyImage(tmp.path(), map.key_images[1], false, cv::Size(64, 48)); });
  EXPECT_NE(resized.find("keys/9.png' is 32x24, not the map's frame size 64x48"), std::string::npos) << resized;
  std::ofstream(tmp.path() / "keys/9.png", std::ios::trunc) << "not a png";
  const std::string undecodable = ErrorOf([&] { ReadKeyImage(tmp.path(), map.key_images[1]); });
  EXPECT_NE(undecodable.find("keys/9.png' is not a PNG or JPEG image"), std::string::npos) << undecodable;
  EXPECT_NE(undecodable.find("rebuild it with `vmap build`"), std::string::npos) << undecodable;
  fs::remove(tmp.path() / "keys/9.png");
  const std::string missing = ErrorOf([&] { KeyImageFile(tmp.path(), map.key_images[1]); });
  EXPECT_NE(missing.find("keys/9.png' is missing"), std::string::npos) << missing;
}

TEST(MapIo, FileNamesThatAreNotUtf8RoundTrip) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  map.input.path = "/data/\xFFrun%1";
  map.key_images[1].source_name = "caf\xE9 9.png";
  WriteMapFiles(map, tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("/data/%FFrun%251"), std::string::npos);
  EXPECT_NE(text.find("caf%E9 9.png"), std::string::npos);
  const VisualMap back = ReadMap(tmp.path());
  EXPECT_EQ(back.input.path, map.input.path);
  EXPECT_EQ(back.key_images[1].source_name, map.key_images[1].source_name);
  EXPECT_EQ(back.key_images[0].source_name, "frame_0");
}

TEST(MapIo, OwnershipNeedsAVmapMapJson) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path() / "map"), tmp.path() / "map");
  EXPECT_EQ(WhyNotAVmapMap(tmp.path() / "map"), "");
  struct Case {
    std::string map_json, expected;
  };
  const std::vector<Case> cases = {
      {"", "it has no map.json"},
      {R"({"type": "FeatureCollection"})", "no \"format\": \"vmap-map\""},
      {R"({"format": "vmap-map"})", "no integer \"schema_version\""},
      {R"({"format": "vmap-map", "schema_version": "1"})", "no integer \"schema_version\""},
      {R"([1, 2])", "no \"format\""},
      {"{oops", "not valid JSON"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path dir = tmp.path() / std::to_string(i);
    fs::create_directories(dir / "src");
    if (!cases[i].map_json.empty()) WriteText(dir / kMapFileName, cases[i].map_json);
    EXPECT_NE(WhyNotAVmapMap(dir).find(cases[i].expected), std::string::npos) << WhyNotAVmapMap(dir);
  }
  // A map.json that is a link to a real map's elsewhere proves nothing.
  fs::create_directories(tmp.path() / "linked");
  fs::create_symlink(tmp.path() / "map" / kMapFileName, tmp.path() / "linked" / kMapFileName);
  EXPECT_NE(WhyNotAVmapMap(tmp.path() / "linked"), "");
}

TEST(MapIo, CameraAndLinkGeometryRoundTrip) {
  testing::ScopedTempDir tmp;
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
  link.translation_sigma_deg = 7.5;
  link.translation_rival_cost_gap = 2.25;
  link.translation_known = false;
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
  EXPECT_DOUBLE_EQ(l.translation_sigma_deg, 7.5);
  EXPECT_DOUBLE_EQ(l.translation_rival_cost_gap, 2.25);
  EXPECT_LT(back.links[0].translation_rival_cost_gap, 0);  // none
  EXPECT_FALSE(l.translation_known);
  EXPECT_LT(back.links[0].translation_sigma_deg, 0);  // no pose: not computed
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
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  // A map as vmap wrote it before links had a geometry: `broken`, no camera, no pose.
  doc["schema_version"] = 1;
  doc["input"].erase("camera");
  doc.erase("conventions");
  for (auto& link : doc["links"]) {
    for (const char* key :
         {"below_tau", "pose", "parallax_px", "parallax_rotation_removed", "homography_share", "planar"}) {
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

// Maps written before links said how well their translation is known: a pose reads as known (what such a map
// claimed), its sigma as not computed.
TEST(MapIo, ReadsMapsWithoutTheTranslationFields) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  map.links[1].has_pose = true;
  map.links[1].t = cv::Vec3d(0, 0, -1);
  WriteMapFiles(map, tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  for (auto& link : doc["links"]) {
    link.erase("translation_sigma_deg");
    link.erase("translation_known");
    link.erase("translation_rival_cost_gap");
  }
  WriteText(tmp.path() / kMapFileName, doc.dump());
  const VisualMap back = ReadMap(tmp.path());
  EXPECT_FALSE(back.links[0].translation_known);
  EXPECT_TRUE(back.links[1].translation_known);
  EXPECT_LT(back.links[1].translation_sigma_deg, 0);
  EXPECT_LT(back.links[1].translation_rival_cost_gap, 0);
}

// The sizes ReadMap checks come from the headers alone, for both kinds of key image.
TEST(MapIo, KeyImageFileSizeReadsPngAndJpegHeaders) {
  testing::ScopedTempDir tmp;
  const cv::Mat image(37, 53, CV_8UC3, cv::Scalar(10, 200, 30));
  ASSERT_TRUE(cv::imwrite((tmp.path() / "a.png").string(), image));
  ASSERT_TRUE(cv::imwrite((tmp.path() / "a.jpg").string(), image));
  ASSERT_TRUE(cv::imwrite((tmp.path() / "p.jpg").string(), image, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}));
  EXPECT_EQ(KeyImageFileSize(tmp.path() / "a.png"), cv::Size(53, 37));
  EXPECT_EQ(KeyImageFileSize(tmp.path() / "a.jpg"), cv::Size(53, 37));
  EXPECT_EQ(KeyImageFileSize(tmp.path() / "p.jpg"), cv::Size(53, 37));
  WriteText(tmp.path() / "text.jpg", "not an image");
  EXPECT_FALSE(KeyImageFileSize(tmp.path() / "text.jpg").has_value());
  EXPECT_FALSE(KeyImageFileSize(tmp.path() / "missing.png").has_value());
}

// map.json is streamed (WriteMapJson) so that a long build's evaluations never sit in memory as one JSON
// document; its text must stay what nlohmann's dump(1) of the whole document gives (MapToJson).
TEST(MapIo, StreamedMapJsonIsTheWholeDocumentsDump) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  map.evaluations.push_back({9, 10, 1.0, 7, 7, true});
  map.evaluations.push_back({9, 11, 1e-300, 4, 1, true});
  map.evaluations.push_back({9, 12, 0.1 + 0.2, 40, 12, true});
  for (bool with_evaluations : {true, false}) {
    VisualMap variant = map;
    if (!with_evaluations) variant.evaluations.clear();
    std::ostringstream streamed;
    WriteMapJson(streamed, variant);
    EXPECT_EQ(streamed.str(), MapToJson(variant) + "\n") << with_evaluations;
  }
  // The evaluations from elsewhere (a build's file), with the map's own list empty: the same text.
  VisualMap without = map;
  without.evaluations.clear();
  std::ostringstream from_source;
  WriteMapJson(from_source, without, [&map](const std::function<void(const Evaluation&)>& fn) {
    for (const Evaluation& e : map.evaluations) fn(e);
  });
  EXPECT_EQ(from_source.str(), MapToJson(map) + "\n");
}

TEST(MapIo, CoverageIsWrittenOnlyWhenKnownAndReadBack) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  WriteMapFiles(map, tmp.path());
  EXPECT_FALSE(ReadMap(tmp.path()).coverage);
  EXPECT_FALSE(nlohmann::json::parse(std::ifstream(tmp.path() / kMapFileName)).contains("coverage"));
  map.coverage = Coverage{20, 100, 119, CoverageEnd::kInterrupted};
  WriteMapFiles(map, tmp.path());
  const VisualMap back = ReadMap(tmp.path());
  ASSERT_TRUE(back.coverage);
  EXPECT_EQ(back.coverage->num_frames, 20);
  EXPECT_EQ(back.coverage->first_source_index, 100);
  EXPECT_EQ(back.coverage->last_source_index, 119);
  EXPECT_EQ(back.coverage->end, CoverageEnd::kInterrupted);
  // More frames covered than the map has is malformed.
  auto doc = nlohmann::json::parse(std::ifstream(tmp.path() / kMapFileName));
  doc["coverage"]["frames"] = 21;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("'coverage.frames' must be an integer from 0 to 20"), std::string::npos)
      << ReadMapError(tmp.path());
}

}  // namespace vmap

namespace vmap {

// A map built within a camera mask keeps it beside map.json, and reads it back only as what vmap wrote: the map's own
// file, of the frames' size, something kept.
TEST(MapIo, CameraMaskRoundTripsAndIsCheckedWhenRead) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  map.camera_mask = cv::Mat(map.input.frame_size, CV_8UC1, cv::Scalar(255));
  map.camera_mask.colRange(0, 10).setTo(0);
  WriteMapFiles(map, tmp.path());
  ASSERT_TRUE(fs::exists(tmp.path() / kCameraMaskFileName));
  const VisualMap back = ReadMap(tmp.path());
  ASSERT_EQ(back.camera_mask.size(), map.camera_mask.size());
  EXPECT_EQ(cv::countNonZero(back.camera_mask != map.camera_mask), 0);
  std::ifstream in(tmp.path() / kMapFileName);
  const nlohmann::json doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc.at("input").at("camera_mask"), kCameraMaskFileName);

  const cv::Mat good = map.camera_mask;
  cv::imwrite((tmp.path() / kCameraMaskFileName).string(), cv::Mat(24, 32, CV_8UC1, cv::Scalar(255)));
  EXPECT_NE(ReadMapError(tmp.path()).find("is not a PNG of the frames' size 64x48"), std::string::npos)
      << ReadMapError(tmp.path());
  cv::imwrite((tmp.path() / kCameraMaskFileName).string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(0)));
  EXPECT_NE(ReadMapError(tmp.path()).find("is black everywhere"), std::string::npos) << ReadMapError(tmp.path());
  cv::imwrite((tmp.path() / kCameraMaskFileName).string(), cv::Mat(48, 64, CV_8UC3, cv::Scalar(255, 255, 255)));
  EXPECT_NE(ReadMapError(tmp.path()).find("is not an 8-bit grey image"), std::string::npos) << ReadMapError(tmp.path());
  fs::remove(tmp.path() / kCameraMaskFileName);
  EXPECT_NE(
      ReadMapError(tmp.path()).find("camera mask '" + (tmp.path() / kCameraMaskFileName).string() + "' is missing"),
      std::string::npos)
      << ReadMapError(tmp.path());

  cv::imwrite((tmp.path() / kCameraMaskFileName).string(), good);
  nlohmann::json named = doc;
  named["input"]["camera_mask"] = "../mask.png";
  testing::WriteText(tmp.path() / kMapFileName, named.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("'input.camera_mask' must be \"camera_mask.png\""), std::string::npos)
      << ReadMapError(tmp.path());
  named["input"]["camera_mask"] = nullptr;  // no mask
  testing::WriteText(tmp.path() / kMapFileName, named.dump());
  EXPECT_TRUE(ReadMap(tmp.path()).camera_mask.empty());
}

}  // namespace vmap
