#include "vmap/sources/dataset_camera.h"

#include <fstream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/sources/frame_source.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

fs::path Shared() { return testing::SharedDir(); }

void WriteText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// An EuRoC cam0/sensor.yaml as the dataset ships it (MH_01_easy's values).
constexpr const char* kEurocSensorYaml = R"(%YAML:1.0
# General sensor definitions.
sensor_type: camera
comment: VI-Sensor cam0 (MT9M034)

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,
        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,
         0.0, 0.0, 0.0, 1.0]

# Camera specific definitions.
rate_hz: 20
resolution: [752, 480]
camera_model: pinhole
intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv
distortion_model: radial-tangential
distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
)";

void WriteImages(const fs::path& directory, int count, cv::Size size) {
  fs::create_directories(directory);
  for (int i = 0; i < count; ++i) {
    cv::imwrite((directory / cv::format("%06d.png", i)).string(), cv::Mat(size, CV_8U, cv::Scalar(40 * i)));
  }
}

}  // namespace

TEST(DatasetCamera, ReadsTheSharedSequencesIntrinsics) {
  SKIP_WITHOUT_SHARED();
  const std::optional<Camera> kitti = FindDatasetCamera((Shared() / "data/kitti07").string(), SourceFormat::kAuto);
  ASSERT_TRUE(kitti);
  EXPECT_DOUBLE_EQ(kitti->fx, 707.0912);
  EXPECT_DOUBLE_EQ(kitti->cx, 601.8873);
  EXPECT_DOUBLE_EQ(kitti->cy, 183.1104);
  EXPECT_EQ(kitti->model, CameraModel::kSimplePinhole);
  const std::optional<Camera> tum = FindDatasetCamera((Shared() / "data/redkitchen").string(), SourceFormat::kAuto);
  ASSERT_TRUE(tum);
  EXPECT_DOUBLE_EQ(tum->fx, 585);
  EXPECT_DOUBLE_EQ(tum->cy, 240);
  // A video's intrinsics.txt lies beside it; this one has radial distortion.
  const std::optional<Camera> video =
      FindDatasetCamera((Shared() / "data/lab_floor/lab_floor.mp4").string(), SourceFormat::kAuto);
  ASSERT_TRUE(video);
  EXPECT_EQ(video->model, CameraModel::kOpenCV);
  EXPECT_DOUBLE_EQ(video->k1, -7.613e-3);
  EXPECT_DOUBLE_EQ(video->fy, 524.245488213640215);
  // No intrinsics beside rccar_room.
  EXPECT_FALSE(FindDatasetCamera((Shared() / "data/rccar_room").string(), SourceFormat::kAuto));
}

TEST(DatasetCamera, KittiColourFramesUseP2AndTheOfficialLayoutWorks) {
  testing::ScopedTempDir tmp;
  WriteImages(tmp.path() / "seq/image_2", 2, {64, 48});
  WriteText(tmp.path() / "seq/times.txt", "0\n0.1\n");
  WriteText(tmp.path() / "seq/calib.txt",
            "P0: 700 0 30 0 0 700 20 0 0 0 1 0\nP1: 700 0 30 -380 0 700 20 0 0 0 1 0\n"
            "P2: 710 0 31 46 0 711 21 0.1 0 0 1 0.006\nP3: 710 0 31 -330 0 711 21 1.9 0 0 1 0.003\n");
  const std::optional<Camera> camera = FindDatasetCamera((tmp.path() / "seq").string(), SourceFormat::kAuto);
  ASSERT_TRUE(camera);
  EXPECT_DOUBLE_EQ(camera->fx, 710);
  EXPECT_DOUBLE_EQ(camera->fy, 711);
  EXPECT_DOUBLE_EQ(camera->cx, 31);
  WriteText(tmp.path() / "bad/calib.txt", "P0: 1 2 3\n");
  EXPECT_THROW(ReadCameraFile((tmp.path() / "bad/calib.txt").string()), InputError);
}

TEST(DatasetCamera, ReadsEurocSensorYamlWithItsExtrinsics) {
  testing::ScopedTempDir tmp;
  WriteText(tmp.path() / "mav0/cam0/sensor.yaml", kEurocSensorYaml);
  WriteText(tmp.path() / "mav0/cam0/data.csv", "#timestamp [ns],filename\n");
  const EurocSensor sensor = ReadEurocSensor((tmp.path() / "mav0/cam0/sensor.yaml").string());
  EXPECT_DOUBLE_EQ(sensor.camera.fx, 458.654);
  EXPECT_DOUBLE_EQ(sensor.camera.cy, 248.375);
  EXPECT_DOUBLE_EQ(sensor.camera.k2, 0.07395907);
  EXPECT_DOUBLE_EQ(sensor.camera.p2, 1.76187114e-05);
  EXPECT_EQ(sensor.camera.size, cv::Size(752, 480));
  EXPECT_EQ(sensor.camera.model, CameraModel::kOpenCV);
  EXPECT_DOUBLE_EQ(sensor.T_BS(0, 1), -0.999880929698);
  EXPECT_DOUBLE_EQ(sensor.T_BS(1, 3), -0.064676986768);
  EXPECT_DOUBLE_EQ(sensor.T_BS(3, 3), 1.0);
  EXPECT_EQ(FindCalibrationFile(tmp.path().string(), SourceFormat::kEuroc),
            (tmp.path() / "mav0/cam0/sensor.yaml").string());
  // --camera accepts the same file.
  EXPECT_DOUBLE_EQ(ParseCameraOption((tmp.path() / "mav0/cam0/sensor.yaml").string()).fx, 458.654);
}

TEST(DatasetCamera, IntrinsicsTextBesideAnImageFolderOrItsParent) {
  testing::ScopedTempDir tmp;
  WriteImages(tmp.path() / "run/images", 2, {64, 48});
  WriteText(tmp.path() / "run/intrinsics.txt", "# a comment\nfx 50.5\nfy 51\ncx 31.5\ncy 23.5  # trailing\n");
  for (const fs::path& input : {tmp.path() / "run", tmp.path() / "run/images"}) {
    const std::optional<Camera> camera = FindDatasetCamera(input.string(), SourceFormat::kAuto);
    ASSERT_TRUE(camera) << input;
    EXPECT_DOUBLE_EQ(camera->fx, 50.5);
    EXPECT_DOUBLE_EQ(camera->cy, 23.5);
  }
  WriteText(tmp.path() / "broken/intrinsics.txt", "fx 50\nfy 50\ncx 32\n");
  try {
    ReadCameraFile((tmp.path() / "broken/intrinsics.txt").string());
    FAIL() << "accepted intrinsics without cy";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'cy'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseCameraOption("no/such/file.yaml"), InputError);
  // A value longer than a file name can be is the camera's error, not a file system error for the caller to blame
  // on its input.
  try {
    ParseCameraOption(std::string(300, 'x'));
    FAIL() << "accepted a camera of 300 x";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.path(), "camera");
  }
  EXPECT_DOUBLE_EQ(ParseCameraOption("500,501,320,240").fy, 501);
}

// COLMAP's cameras.txt, as COLMAP writes it: its first camera, the principal point moved from COLMAP's pixel centres
// (the top-left one at 0.5, 0.5) to OpenCV's (at 0, 0).
TEST(DatasetCamera, ReadsColmapCamerasTxt) {
  testing::ScopedTempDir tmp;
  const std::string header =
      "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      "# Number of cameras: 1\n";
  WriteText(tmp.path() / "pinhole/cameras.txt", header + "1 PINHOLE 640 480 525.5 524.5 320.5 240.5\n");
  const Camera pinhole = ReadCameraFile((tmp.path() / "pinhole/cameras.txt").string());
  EXPECT_EQ(pinhole.K(), cv::Matx33d(525.5, 0, 320, 0, 524.5, 240, 0, 0, 1));
  EXPECT_EQ(pinhole.size, cv::Size(640, 480));
  WriteText(tmp.path() / "radial/cameras.txt", header + "1 SIMPLE_RADIAL 640 480 500 320 240 -0.125\n");
  const Camera radial = ReadCameraFile((tmp.path() / "radial/cameras.txt").string());
  EXPECT_EQ(radial.fx, 500);
  EXPECT_EQ(radial.fy, 500);
  EXPECT_EQ(radial.cx, 319.5);
  EXPECT_EQ(radial.k1, -0.125);
  EXPECT_EQ(radial.k2, 0.0);
  WriteText(tmp.path() / "fisheye/cameras.txt", "1 OPENCV_FISHEYE 640 480 300 301 320 240 0.1 0.01 0.001 0.0001\n");
  const Camera fisheye = ReadCameraFile((tmp.path() / "fisheye/cameras.txt").string());
  EXPECT_TRUE(fisheye.is_fisheye());
  EXPECT_EQ(fisheye.k4, 0.0001);
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"1 THIN_PRISM_FISHEYE 640 480 1 2 3 4 5 6 7 8 9 10 11 12\n", "model THIN_PRISM_FISHEYE is not read"},
           {"1 PINHOLE 640 480 525 525 320\n", "WIDTH HEIGHT and 4 parameters, not 5 numbers"},
           {"1 PINHOLE 640 480 525 x 320 240\n", "'x' is not a number"}}) {
    WriteText(tmp.path() / "bad/cameras.txt", text);
    try {
      ReadCameraFile((tmp.path() / "bad/cameras.txt").string());
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

// "run/images/" as tab completion writes it, and "run/images/.", are the folder "run/images": what lies beside it in
// "run" (its times and its camera) is found as for "run/images" (the slash lost both, without a word).
TEST(DatasetCamera, WhatLiesBesideAnImageFolderIsFoundHoweverTheFolderIsNamed) {
  testing::ScopedTempDir tmp;
  WriteImages(tmp.path() / "run/images", 3, {64, 48});
  WriteText(tmp.path() / "run/intrinsics.txt", "fx 50\nfy 50\ncx 31.5\ncy 23.5\n");
  WriteText(tmp.path() / "run/timestamps.txt", "000000.png 10.0\n000001.png 10.5\n000002.png 11.25\n");
  for (const std::string name : {"run/images", "run/images/", "run/images/."}) {
    auto source = OpenFrameSource((tmp.path() / name).string());
    std::vector<double> times;
    while (std::optional<Frame> frame = source->Next()) times.push_back(frame->timestamp);
    EXPECT_EQ(times, (std::vector<double>{10.0, 10.5, 11.25})) << name;
    ASSERT_TRUE(source->info().camera) << name;
    EXPECT_DOUBLE_EQ(source->info().camera->fx, 50.0) << name;
  }
}

TEST(DatasetCamera, FrameSourceCarriesTheCameraScaledWithResize) {
  testing::ScopedTempDir tmp;
  WriteImages(tmp.path() / "run", 3, {640, 480});
  WriteText(tmp.path() / "run/intrinsics.txt", "fx 500\nfy 500\ncx 319.5\ncy 239.5\n");
  FrameSourceOptions options;
  options.resize = "320";
  auto source = OpenFrameSource((tmp.path() / "run").string(), options);
  EXPECT_FALSE(source->info().camera);  // known once the first frame tells the size
  ASSERT_TRUE(source->Next());
  ASSERT_TRUE(source->info().camera);
  EXPECT_DOUBLE_EQ(source->info().camera->fx, 250);
  EXPECT_DOUBLE_EQ(source->info().camera->cx, 159.5);
  EXPECT_EQ(source->info().camera->size, cv::Size(320, 240));
  // --camera none ignores the input's own; --camera replaces it.
  options.camera = "none";
  source = OpenFrameSource((tmp.path() / "run").string(), options);
  ASSERT_TRUE(source->Next());
  EXPECT_FALSE(source->info().camera);
  options.camera = "400,400,320,240";
  source = OpenFrameSource((tmp.path() / "run").string(), options);
  ASSERT_TRUE(source->Next());
  EXPECT_DOUBLE_EQ(source->info().camera->fx, 200);
  // Intrinsics that cannot belong to these frames are an error at the first frame.
  options.camera = "400,400,900,700";
  source = OpenFrameSource((tmp.path() / "run").string(), options);
  EXPECT_THROW(source->Next(), InputError);
}

}  // namespace vmap
