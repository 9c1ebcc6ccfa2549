#include "vmap/geometry/camera.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

TEST(Camera, PicksTheSimplestColmapModelAndRoundTripsItsParameters) {
  EXPECT_EQ(Camera::Make(500, 500, 320, 240).model, CameraModel::kSimplePinhole);
  EXPECT_EQ(Camera::Make(500, 510, 320, 240).model, CameraModel::kPinhole);
  EXPECT_EQ(Camera::Make(500, 500, 320, 240, {0.1, 0, 0, 0}).model, CameraModel::kOpenCV);
  EXPECT_EQ(Camera::Make(500, 500, 320, 240, {0.1, 0, 0, 0, 0.01}).model, CameraModel::kFullOpenCV);
  for (const Camera& camera :
       {Camera::Make(500, 500, 320, 240), Camera::Make(500, 510, 321, 239),
        Camera::Make(500, 510, 320, 240, {-0.2, 0.05, 1e-3, -2e-3}),
        Camera::Make(500, 510, 320, 240, {-0.2, 0.05, 1e-3, -2e-3, 0.01}),
        Camera::Make(500, 510, 320, 240, {-0.2, 0.05, 1e-3, -2e-3, 0.01, 0.1, 0.02, 0.003}),
        Camera::FromParams(CameraModel::kOpenCVFisheye, {500, 510, 320, 240, 0.1, -0.02, 0.003, -0.0004})}) {
    const Camera back = Camera::FromParams(camera.model, camera.params(), {640, 480});
    EXPECT_EQ(ParseCameraModel(CameraModelName(camera.model)), camera.model);
    EXPECT_EQ(back.K(), camera.K());
    EXPECT_EQ(back.distortion(), camera.distortion());
  }
  EXPECT_EQ(CameraModelName(CameraModel::kPinhole), "PINHOLE");
  EXPECT_EQ(CameraModelName(CameraModel::kOpenCV), "OPENCV");
  EXPECT_EQ(Camera::Make(500, 500, 320, 240, {0.1, 0, 0, 0, 0, 0.01, 0, 0}).model, CameraModel::kFullOpenCV);
  EXPECT_EQ(CameraModelName(CameraModel::kOpenCVFisheye), "OPENCV_FISHEYE");
  // A fisheye lens with zero coefficients is still the equidistant projection, not a pinhole.
  EXPECT_TRUE(Camera::FromParams(CameraModel::kOpenCVFisheye, {500, 500, 320, 240, 0, 0, 0, 0}).has_distortion());
  EXPECT_THROW(ParseCameraModel("FISHEYE"), InputError);
  EXPECT_THROW(Camera::Make(500, 500, 320, 240, {0.1, 0, 0, 0, 0, 0.01}), InputError);  // 6 coefficients
  EXPECT_THROW(Camera::Make(500, 500, 320, 240, {0.1, 0, 0, 0, 0, 0, 0, 0, 0.01, 0, 0, 0}), InputError);  // s1
  EXPECT_THROW(Camera::FromParams(CameraModel::kPinhole, {1, 2, 3}), InputError);
}

TEST(Camera, ParsesTheCameraOptionText) {
  const Camera plain = ParseCameraText("525.5,524,319.5,239.5");
  EXPECT_EQ(plain.model, CameraModel::kPinhole);
  EXPECT_DOUBLE_EQ(plain.fy, 524);
  EXPECT_DOUBLE_EQ(plain.cx, 319.5);
  const Camera distorted = ParseCameraText("500 500 320 240 -0.1 0.02 0.001 0.002");
  EXPECT_EQ(distorted.model, CameraModel::kOpenCV);
  EXPECT_DOUBLE_EQ(distorted.p2, 0.002);
  EXPECT_DOUBLE_EQ(ParseCameraText("500,500,320,240,-0.1,0.02,0,0,0.003").k3, 0.003);
  EXPECT_DOUBLE_EQ(ParseCameraText("500,500,320,240,-0.1,0.02,0,0,0.003,0.1,0.01,0.001").k5, 0.01);
  for (const char* bad : {"500,500,320", "500,500,320,240,0.1", "a,b,c,d", "-500,500,320,240", "0,500,320,240"}) {
    EXPECT_THROW(ParseCameraText(bad), InputError) << bad;
  }
}

TEST(Camera, ReadsOpenCvCalibrationFilesInYamlAndJson) {
  testing::ScopedTempDir tmp;
  const cv::Matx33d K(612.5, 0, 331.25, 0, 611.0, 242.75, 0, 0, 1);
  const cv::Mat distortion = (cv::Mat_<double>(5, 1) << -0.21, 0.07, 0.0012, -0.0008, -0.011);
  for (const char* name : {"calibration.yaml", "calibration.json"}) {
    // What OpenCV's calibration sample writes.
    cv::FileStorage fs((tmp.path() / name).string(), cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480 << "camera_matrix" << cv::Mat(K) << "distortion_coefficients"
       << distortion << "avg_reprojection_error" << 0.31;
    fs.release();
    const Camera camera = ReadOpenCvCameraFile((tmp.path() / name).string());
    EXPECT_EQ(camera.K(), K) << name;
    EXPECT_EQ(camera.size, cv::Size(640, 480));
    EXPECT_EQ(camera.model, CameraModel::kFullOpenCV);
    EXPECT_DOUBLE_EQ(camera.k3, -0.011);
    EXPECT_DOUBLE_EQ(camera.p1, 0.0012);
  }
  {
    // A fisheye calibration, its model named as ROS's camera_calibration names it.
    cv::FileStorage fs((tmp.path() / "fisheye.yaml").string(), cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480 << "camera_matrix" << cv::Mat(K) << "distortion_model"
       << "equidistant"
       << "distortion_coefficients" << (cv::Mat_<double>(4, 1) << 0.05, -0.01, 0.002, -0.0003);
  }
  const Camera fisheye = ReadOpenCvCameraFile((tmp.path() / "fisheye.yaml").string());
  EXPECT_EQ(fisheye.model, CameraModel::kOpenCVFisheye);
  EXPECT_EQ(fisheye.distortion(), (std::vector<double>{0.05, -0.01, 0.002, -0.0003}));
  {
    cv::FileStorage fs((tmp.path() / "unknown_model.yaml").string(), cv::FileStorage::WRITE);
    fs << "camera_matrix" << cv::Mat(K) << "distortion_model"
       << "kannala_brandt"
       << "distortion_coefficients" << distortion;
  }
  EXPECT_THROW(ReadOpenCvCameraFile((tmp.path() / "unknown_model.yaml").string()), InputError);
  {
    cv::FileStorage fs((tmp.path() / "no_matrix.yaml").string(), cv::FileStorage::WRITE);
    fs << "image_width" << 640;
  }
  try {
    ReadOpenCvCameraFile((tmp.path() / "no_matrix.yaml").string());
    FAIL() << "a file without camera_matrix was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera_matrix"), std::string::npos) << e.what();
  }
  // What ROS's camera_calibration writes (ost.yaml): no "%YAML:1.0" line, matrices as {rows, cols, data}.
  std::ofstream(tmp.path() / "ost.yaml") << "image_width: 640\nimage_height: 480\ncamera_name: narrow_stereo\n"
                                            "camera_matrix:\n  rows: 3\n  cols: 3\n"
                                            "  data: [612.5, 0, 331.25, 0, 611.0, 242.75, 0, 0, 1]\n"
                                            "distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n"
                                            "  cols: 5\n  data: [-0.21, 0.07, 0.0012, -0.0008, -0.011]\n"
                                            "rectification_matrix:\n  rows: 3\n  cols: 3\n"
                                            "  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n";
  const Camera ros = ReadOpenCvCameraFile((tmp.path() / "ost.yaml").string());
  EXPECT_EQ(ros.K(), K);
  EXPECT_EQ(ros.size, cv::Size(640, 480));
  EXPECT_DOUBLE_EQ(ros.k3, -0.011);
  std::ofstream(tmp.path() / "short.yaml") << "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [612.5, 0, 331.25]\n";
  try {
    ReadOpenCvCameraFile((tmp.path() / "short.yaml").string());
    FAIL() << "a 3x3 matrix of 3 numbers was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a 3x3 matrix holds 3 numbers"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ost.yaml"), std::string::npos) << e.what() << " names the formats";
  }
}

// The scaled camera must describe the image cv::resize produces: a bright dot rendered at a sub-pixel position
// with the full camera is found, after resizing, where the scaled camera projects the same point.
TEST(Camera, ScaledCameraMatchesTheResizedImage) {
  const Camera full = Camera::Make(800, 800, 639.5, 359.5, {}, {1280, 720});
  const cv::Vec3d X(0.31, -0.17, 2.0);
  const auto project = [&](const Camera& c) {
    return cv::Point2d(c.fx * X[0] / X[2] + c.cx, c.fy * X[1] / X[2] + c.cy);
  };
  const cv::Point2d at = project(full);
  cv::Mat image(720, 1280, CV_32F);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const double d2 = (x - at.x) * (x - at.x) + (y - at.y) * (y - at.y);
      image.at<float>(y, x) = static_cast<float>(std::exp(-d2 / (2 * 6.0 * 6.0)));
    }
  }
  for (const cv::Size size : {cv::Size(640, 360), cv::Size(320, 180), cv::Size(1000, 500)}) {
    cv::Mat resized;
    cv::resize(image, resized, size, 0, 0, cv::INTER_AREA);
    const cv::Moments m = cv::moments(resized);
    const cv::Point2d found(m.m10 / m.m00, m.m01 / m.m00);
    const cv::Point2d expected = project(full.ScaledTo(size));
    EXPECT_NEAR(found.x, expected.x, 0.05) << size;
    EXPECT_NEAR(found.y, expected.y, 0.05) << size;
  }
}

TEST(Camera, CameraForFramesScalesChecksAndRefuses) {
  Camera calibrated = Camera::Make(1000, 1000, 639.5, 479.5, {}, {1280, 960});
  calibrated.origin = "calib.yaml";
  // Calibrated at 1280x960, frames stored at 640x480 and resized to 320x240.
  const Camera scaled = CameraForFrames(calibrated, {640, 480}, {320, 240});
  EXPECT_DOUBLE_EQ(scaled.fx, 250);
  EXPECT_DOUBLE_EQ(scaled.cx, 159.5);
  EXPECT_EQ(scaled.size, cv::Size(320, 240));
  // Another aspect ratio cannot be the same sensor's: refused with a message naming the file.
  try {
    CameraForFrames(calibrated, {640, 360}, {640, 360});
    FAIL() << "accepted a calibration of another aspect ratio";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("calib.yaml"), std::string::npos) << e.what();
  }
  // Without a size: the principal point must lie in the frames.
  const Camera unsized = Camera::Make(1000, 1000, 959.5, 539.5);  // a 1920x1080 calibration
  EXPECT_THROW(CameraForFrames(unsized, {640, 480}, {640, 480}), InputError);
  EXPECT_DOUBLE_EQ(CameraForFrames(unsized, {1920, 1080}, {960, 540}).fx, 500);
}

TEST(Camera, NormalizePointsUndoesOpenCvsProjection) {
  const Camera camera = Camera::Make(520, 515, 318, 241, {-0.28, 0.09, 0.0012, -0.0007, -0.01});
  std::vector<cv::Point3d> points;
  for (double x : {-0.5, -0.1, 0.3, 0.6})
    for (double y : {-0.4, 0.0, 0.35}) points.emplace_back(x, y, 1.0);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(points, cv::Vec3d(), cv::Vec3d(), cv::Mat(camera.K()), camera.distortion(), projected);
  const std::vector<cv::Point2f> pixels(projected.begin(), projected.end());
  const std::vector<cv::Point2d> normalized = NormalizePoints(camera, pixels);
  const std::vector<cv::Point2d> pinhole = UndistortPixels(camera, pixels);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(normalized[i].x, points[i].x, 2e-5);
    EXPECT_NEAR(normalized[i].y, points[i].y, 2e-5);
    EXPECT_NEAR(pinhole[i].x, camera.fx * points[i].x + camera.cx, 0.01);
  }
}

// Rational (k4..k6) and fisheye lenses: NormalizePoints inverts OpenCV's own projection for each model, the
// fisheye's out to wide angles (rays 61 degrees off axis).
TEST(Camera, NormalizePointsUndoesRationalAndFisheyeProjections) {
  std::vector<cv::Point3d> points;
  for (double x : {-1.6, -0.5, 0.0, 0.3, 1.2})
    for (double y : {-0.9, 0.0, 0.7}) points.emplace_back(x, y, 1.0);
  // A rational calibration as wide lenses get them (numerator and denominator nearly cancel), over the image.
  std::vector<cv::Point3d> in_view;
  for (double x : {-0.6, -0.2, 0.3, 0.6})
    for (double y : {-0.45, 0.0, 0.4}) in_view.emplace_back(x, y, 1.0);
  const Camera rational = Camera::Make(520, 515, 318, 241, {0.9, 0.2, 0.0012, -0.0007, 0.005, 1.25, 0.4, 0.02});
  ASSERT_EQ(rational.model, CameraModel::kFullOpenCV);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(in_view, cv::Vec3d(), cv::Vec3d(), cv::Mat(rational.K()), rational.distortion(), projected);
  std::vector<cv::Point2d> normalized =
      NormalizePoints(rational, std::vector<cv::Point2f>(projected.begin(), projected.end()));
  for (size_t i = 0; i < in_view.size(); ++i) {
    EXPECT_NEAR(normalized[i].x, in_view[i].x, 1e-4) << i;
    EXPECT_NEAR(normalized[i].y, in_view[i].y, 1e-4) << i;
  }
  const Camera fisheye =
      Camera::FromParams(CameraModel::kOpenCVFisheye, {300, 302, 318, 241, 0.08, -0.02, 0.004, -0.0005});
  cv::fisheye::projectPoints(points, projected, cv::Vec3d(), cv::Vec3d(), cv::Mat(fisheye.K()), fisheye.distortion());
  normalized = NormalizePoints(fisheye, std::vector<cv::Point2f>(projected.begin(), projected.end()));
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(normalized[i].x, points[i].x, 1e-4) << i;
    EXPECT_NEAR(normalized[i].y, points[i].y, 1e-4) << i;
  }
  // The equidistant projection is not the pinhole's: without the fisheye model these rays would be off.
  const Camera pinhole = Camera::Make(300, 302, 318, 241);
  const std::vector<cv::Point2d> as_pinhole =
      NormalizePoints(pinhole, std::vector<cv::Point2f>(projected.begin(), projected.end()));
  EXPECT_GT(std::abs(as_pinhole[0].x - points[0].x), 0.3);
}

}  // namespace vmap
