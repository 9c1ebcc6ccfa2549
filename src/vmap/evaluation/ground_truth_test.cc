#include "vmap/evaluation/ground_truth.h"

#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "vmap/core/error.h"
#include "vmap/geometry/relative_pose.h"
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

KeyImage Key(int source_index, double timestamp) {
  KeyImage key;
  key.frame_index = 0;  // deliberately not the source index: poses are tied to the input's own numbering
  key.source_index = source_index;
  key.timestamp = timestamp;
  return key;
}

cv::Vec3d Translation(const cv::Matx44d& T) { return {T(0, 3), T(1, 3), T(2, 3)}; }

}  // namespace

TEST(GroundTruth, QuaternionsFollowTheHamiltonConvention) {
  // 90 degrees about z: x goes to y.
  const double h = std::sqrt(0.5);
  const cv::Matx33d R = QuaternionToRotation(h, 0, 0, h);
  const cv::Vec3d x = R * cv::Vec3d(1, 0, 0);
  EXPECT_NEAR(x[1], 1.0, 1e-12);
  EXPECT_NEAR(x[0], 0.0, 1e-12);
  // Not normalised on input: normalised first.
  const cv::Matx33d same = QuaternionToRotation(2 * h, 0, 0, 2 * h);
  EXPECT_LT(cv::norm(same - R), 1e-12);
  // Against OpenCV's axis-angle for a general rotation.
  const cv::Vec3d axis = cv::normalize(cv::Vec3d(0.3, -0.5, 0.8));
  const double angle = 0.7;
  cv::Matx33d expected;
  cv::Rodrigues(axis * angle, expected);
  const cv::Matx33d q = QuaternionToRotation(std::cos(angle / 2), axis[0] * std::sin(angle / 2),
                                             axis[1] * std::sin(angle / 2), axis[2] * std::sin(angle / 2));
  EXPECT_LT(cv::norm(q - expected), 1e-12);
}

TEST(GroundTruth, RelativePoseMapsPointsFromTheFirstCameraToTheSecond) {
  cv::Matx44d T_wa = cv::Matx44d::eye(), T_wb = cv::Matx44d::eye();
  cv::Matx33d Ra, Rb;
  cv::Rodrigues(cv::Vec3d(0.1, -0.2, 0.05), Ra);
  cv::Rodrigues(cv::Vec3d(-0.05, 0.3, 0.1), Rb);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      T_wa(r, c) = Ra(r, c);
      T_wb(r, c) = Rb(r, c);
    }
  }
  T_wa(0, 3) = 1.0;
  T_wb(2, 3) = -2.0;
  cv::Matx33d R;
  cv::Vec3d t;
  RelativeFromCameraToWorld(T_wa, T_wb, &R, &t);
  // A point given in a's frame, taken to the world and back into b's frame.
  const cv::Vec4d X_a(0.3, -0.2, 4.0, 1.0);
  const cv::Vec4d X_w = T_wa * X_a;
  const cv::Vec4d X_b = T_wb.inv() * X_w;
  const cv::Vec3d predicted = R * cv::Vec3d(X_a[0], X_a[1], X_a[2]) + t;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(predicted[i], X_b[i], 1e-12);
}

// KITTI's rotations are printed to 6 digits. Read as they are, the relative rotation between two of them is a
// rounding away from orthonormal, and a perfect estimate of it was scored some 0.005 degrees wrong.
TEST(GroundTruth, KittiRotationsAreReadAsRotations) {
  cv::Matx33d Ra, Rb;
  cv::Rodrigues(cv::Vec3d(0.01, 1.2, -0.02), Ra);
  cv::Rodrigues(cv::Vec3d(0.012, 1.25, -0.018), Rb);
  std::string text;
  for (const cv::Matx33d& R : {Ra, Rb}) {
    for (int r = 0; r < 3; ++r) text += fmt::format("{:.6e} {:.6e} {:.6e} {} ", R(r, 0), R(r, 1), R(r, 2), r);
    text += "\n";
  }
  testing::ScopedTempDir tmp;
  WriteText(tmp.path() / "rounded.txt", text);
  const GroundTruth truth = ReadGroundTruth((tmp.path() / "rounded.txt").string(), GroundTruthFormat::kKitti);
  ASSERT_EQ(truth.camera_to_world.size(), 2u);
  for (const cv::Matx44d& T : truth.camera_to_world) {
    const cv::Matx33d R = T.get_minor<3, 3>(0, 0);
    EXPECT_LT(cv::norm(R.t() * R - cv::Matx33d::eye(), cv::NORM_INF), 1e-14);
    EXPECT_NEAR(cv::determinant(R), 1.0, 1e-14);
  }
  EXPECT_NEAR(truth.camera_to_world[0](0, 0), Ra(0, 0), 1e-6);  // the nearest rotation, not another one
  cv::Matx33d R_true;
  cv::Vec3d t_true;
  RelativeFromCameraToWorld(truth.camera_to_world[0], truth.camera_to_world[1], &R_true, &t_true);
  EXPECT_NEAR(RotationAngleDeg(R_true), RotationAngleDeg(Ra.t() * Rb), 1e-4);
}

TEST(GroundTruth, DetectsAndReadsTheThreeFormats) {
  testing::ScopedTempDir tmp;
  WriteText(tmp.path() / "kitti.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.5 0 1 0 0 0 0 1 2\n");
  WriteText(tmp.path() / "tum.txt",
            "# timestamp tx ty tz qx qy qz qw\n10.0 1 2 3 0 0 0 1\n10.1 1 2 4 0 0 0.7071068 0.7071068\n");
  WriteText(tmp.path() / "euroc.csv",
            "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []\n"
            "1403636579758555392,4.6,-1.8,0.8,0.7071068,0,0,0.7071068,0,0,0,0,0,0,0,0,0\n");
  EXPECT_EQ(DetectGroundTruthFormat((tmp.path() / "kitti.txt").string()), GroundTruthFormat::kKitti);
  EXPECT_EQ(DetectGroundTruthFormat((tmp.path() / "tum.txt").string()), GroundTruthFormat::kTum);
  EXPECT_EQ(DetectGroundTruthFormat((tmp.path() / "euroc.csv").string()), GroundTruthFormat::kEuroc);

  const GroundTruth kitti = ReadGroundTruth((tmp.path() / "kitti.txt").string());
  ASSERT_EQ(kitti.camera_to_world.size(), 2u);
  EXPECT_TRUE(kitti.timestamps.empty());
  EXPECT_EQ(Translation(kitti.camera_to_world[1]), cv::Vec3d(0.5, 0, 2));

  const GroundTruth tum = ReadGroundTruth((tmp.path() / "tum.txt").string());
  ASSERT_EQ(tum.timestamps.size(), 2u);
  EXPECT_EQ(Translation(tum.camera_to_world[1]), cv::Vec3d(1, 2, 4));
  // qz = qw: 90 degrees about z (TUM orders the quaternion x y z w).
  EXPECT_NEAR(tum.camera_to_world[1](1, 0), 1.0, 1e-6);

  // EuRoC orders it w x y z, gives the body's pose and nanoseconds; the camera's pose is T_wb T_bc.
  cv::Matx44d body_to_camera = cv::Matx44d::eye();
  body_to_camera(0, 3) = 0.1;  // the camera sits 10 cm along the body's x axis
  const GroundTruth euroc =
      ReadGroundTruth((tmp.path() / "euroc.csv").string(), GroundTruthFormat::kAuto, body_to_camera);
  ASSERT_EQ(euroc.timestamps.size(), 1u);
  EXPECT_NEAR(euroc.timestamps[0], 1403636579.758555392, 1e-6);
  EXPECT_NEAR(euroc.camera_to_world[0](1, 0), 1.0, 1e-6);
  // Body rotated 90 degrees about z: its x axis points along world y, so the camera is 10 cm further in y.
  EXPECT_NEAR(euroc.camera_to_world[0](0, 3), 4.6, 1e-6);
  EXPECT_NEAR(euroc.camera_to_world[0](1, 3), -1.7, 1e-6);

  WriteText(tmp.path() / "garbage.txt", "1 2 3\n");
  EXPECT_THROW(DetectGroundTruthFormat((tmp.path() / "garbage.txt").string()), InputError);
  WriteText(tmp.path() / "short.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0\n");
  try {
    ReadGroundTruth((tmp.path() / "short.txt").string(), GroundTruthFormat::kKitti);
    FAIL() << "a short line was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  WriteText(tmp.path() / "unsorted.txt", "2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n");
  EXPECT_THROW(ReadGroundTruth((tmp.path() / "unsorted.txt").string()), InputError);
  EXPECT_THROW(ReadGroundTruth((tmp.path() / "missing.txt").string()), InputError);
}

// Issue 38: all-zero or 1e300 matrices were read as poses and gave 120-degree errors; a zero quaternion the
// identity.
TEST(GroundTruth, LinesThatAreNoPoseAreRefusedNamingTheLine) {
  testing::ScopedTempDir tmp;
  const std::string good = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const struct {
    const char* name;
    std::string text;
    GroundTruthFormat format;
  } cases[] = {
      {"zeros.txt", good + "0 0 0 0 0 0 0 0 0 0 0 0\n", GroundTruthFormat::kKitti},
      {"huge.txt", good + "1e300 0 0 0 0 1e300 0 0 0 0 1e300 0\n", GroundTruthFormat::kKitti},
      {"far.txt", good + "1 0 0 1e300 0 1 0 0 0 0 1 0\n", GroundTruthFormat::kKitti},
      {"mirror.txt", good + "-1 0 0 0 0 1 0 0 0 0 1 0\n", GroundTruthFormat::kKitti},
      {"tum.txt", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 0\n", GroundTruthFormat::kTum},
      {"euroc.csv", "1000,0,0,0,1,0,0,0\n2000,0,0,0,3,0,0,0\n", GroundTruthFormat::kEuroc},
  };
  for (const auto& c : cases) {
    WriteText(tmp.path() / c.name, c.text);
    try {
      ReadGroundTruth((tmp.path() / c.name).string(), c.format);
      ADD_FAILURE() << c.name << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("line 2 is not a pose"), std::string::npos) << c.name << ": " << e.what();
    }
  }
  // Poses printed to 6 digits, as KITTI's are, stay poses.
  WriteText(tmp.path() / "printed.txt", good +
                                            "9.999978e-01 5.272628e-04 -2.066935e-03 -4.690294e-02 "
                                            "-5.296506e-04 9.999992e-01 -1.154865e-03 -2.839928e-02 "
                                            "2.066324e-03 1.155958e-03 9.999971e-01 8.586941e-01\n");
  EXPECT_EQ(ReadGroundTruth((tmp.path() / "printed.txt").string()).camera_to_world.size(), 2u);
}

TEST(GroundTruth, KeyImagesTakeTheirPoseByFrameNumberOrByNearestTimestamp) {
  GroundTruth kitti;
  kitti.format = GroundTruthFormat::kKitti;
  for (int i = 0; i < 5; ++i) {
    cv::Matx44d T = cv::Matx44d::eye();
    T(2, 3) = i;
    kitti.camera_to_world.push_back(T);
  }
  EXPECT_EQ(Translation(*KeyImagePose(kitti, Key(3, -1), 0.02))[2], 3.0);
  EXPECT_FALSE(KeyImagePose(kitti, Key(5, -1), 0.02));
  // A KITTI image's file number wins over its position in the listing, which images missing from the
  // sequence shift (000004.png read as the fourth image is still frame 4).
  KeyImage numbered = Key(3, -1);
  numbered.source_name = "000004.png";
  EXPECT_EQ(Translation(*KeyImagePose(kitti, numbered, 0.02))[2], 4.0);
  numbered.source_name = "000005.png";
  EXPECT_FALSE(KeyImagePose(kitti, numbered, 0.02));
  numbered.source_name = "left_4.png";  // no number: by position
  EXPECT_EQ(Translation(*KeyImagePose(kitti, numbered, 0.02))[2], 3.0);

  GroundTruth tum = kitti;
  tum.format = GroundTruthFormat::kTum;
  tum.timestamps = {100.00, 100.10, 100.20, 100.30, 100.40};
  EXPECT_EQ(Translation(*KeyImagePose(tum, Key(0, 100.21), 0.02))[2], 2.0);  // nearest, 10 ms away
  EXPECT_EQ(Translation(*KeyImagePose(tum, Key(0, 100.29), 0.02))[2], 3.0);  // nearest is the later one
  EXPECT_EQ(Translation(*KeyImagePose(tum, Key(0, 100.0), 0.02))[2], 0.0);
  EXPECT_FALSE(KeyImagePose(tum, Key(0, 100.15), 0.02));  // 50 ms from any pose
  EXPECT_FALSE(KeyImagePose(tum, Key(0, 99.0), 0.02));
  EXPECT_FALSE(KeyImagePose(tum, Key(2, -1), 0.02));  // no timestamp: never by index
}

TEST(GroundTruth, FindsTheGroundTruthOfEachLayout) {
  SKIP_WITHOUT_SHARED();
  const std::optional<GroundTruth> kitti = FindGroundTruth((Shared() / "data/kitti07").string(), SourceFormat::kAuto);
  ASSERT_TRUE(kitti);
  EXPECT_EQ(kitti->format, GroundTruthFormat::kKitti);
  EXPECT_EQ(kitti->camera_to_world.size(), 160u);
  EXPECT_NEAR(kitti->camera_to_world[1](2, 3), 0.09154274, 1e-9);  // 9 cm forward after one frame
  const std::optional<GroundTruth> tum = FindGroundTruth((Shared() / "data/redkitchen").string(), SourceFormat::kAuto);
  ASSERT_TRUE(tum);
  EXPECT_EQ(tum->format, GroundTruthFormat::kTum);
  EXPECT_EQ(tum->camera_to_world.size(), 1000u);
  EXPECT_FALSE(FindGroundTruth((Shared() / "data/rccar_room").string(), SourceFormat::kAuto));
}

TEST(GroundTruth, FindsKittiPosesInTheOfficialLayout) {
  testing::ScopedTempDir tmp;
  // dataset/sequences/07/{image_0, times.txt} and dataset/poses/07.txt
  fs::create_directories(tmp.path() / "dataset/sequences/07/image_0");
  WriteText(tmp.path() / "dataset/poses/07.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0.9\n");
  const std::optional<GroundTruth> truth =
      FindGroundTruth((tmp.path() / "dataset/sequences/07").string(), SourceFormat::kKitti);
  ASSERT_TRUE(truth);
  EXPECT_EQ(truth->camera_to_world.size(), 2u);
  // The sequence named with a trailing slash (tab completion) or as "07/.": the same folder.
  for (const char* name : {"dataset/sequences/07/", "dataset/sequences/07/."}) {
    const std::optional<GroundTruth> same = FindGroundTruth((tmp.path() / name).string(), SourceFormat::kKitti);
    ASSERT_TRUE(same) << name;
    EXPECT_EQ(same->camera_to_world.size(), 2u) << name;
  }
  EXPECT_EQ(ParseGroundTruthFormat("euroc"), GroundTruthFormat::kEuroc);
  EXPECT_THROW(ParseGroundTruthFormat("colmap"), InputError);
}

}  // namespace vmap
