#pragma once
// Ground-truth camera poses of a sequence, as the datasets store them.
//
// Every format holds camera-to-world poses T_wc (X_world = R_wc X_cam + t_wc); they differ in how a pose
// is tied to a frame and in the order of the quaternion:
//   kitti  poses.txt: one line per image of the sequence, 12 numbers = the 3x4 matrix [R_wc | t_wc] row by
//          row, of camera 0 (the left grey camera); line i belongs to image i: the key image whose file is
//          numbered i (000123.png), else the one whose source_index is i.
//   tum    groundtruth.txt: "timestamp tx ty tz qx qy qz qw" (quaternion x, y, z, w) of the camera; tied to
//          a key image by its timestamp (the nearest pose within max_time_difference, as TUM's associate.py).
//   euroc  state_groundtruth_estimate0/data.csv: "timestamp_ns, px, py, pz, qw, qx, qy, qz, ..." (quaternion
//          w first) of the body (IMU) frame, T_wb; the camera's pose is T_wb T_bc with T_bc = T_BS of the
//          camera's sensor.yaml. Tied by timestamp as tum.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/map/visual_map.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

enum class GroundTruthFormat { kAuto, kKitti, kTum, kEuroc };
inline constexpr EnumName<GroundTruthFormat> kGroundTruthFormatNames[] = {{GroundTruthFormat::kAuto, "auto"},
                                                                          {GroundTruthFormat::kKitti, "kitti"},
                                                                          {GroundTruthFormat::kTum, "tum"},
                                                                          {GroundTruthFormat::kEuroc, "euroc"}};
GroundTruthFormat ParseGroundTruthFormat(const std::string& name);
std::string GroundTruthFormatName(GroundTruthFormat format);

struct GroundTruth {
  std::string path;
  GroundTruthFormat format = GroundTruthFormat::kAuto;
  std::vector<double> timestamps;            // seconds, ascending; empty for kitti (indexed by image)
  std::vector<cv::Matx44d> camera_to_world;  // T_wc of the camera, one per line
  // kitti: line N is the image whose file is numbered N (a KITTI sequence's image_0/000123.png, which stays right
  // when an image is missing); otherwise the key image's position in the input. Only a KITTI sequence's file names
  // are its frame numbers: an image folder numbered from 1 (ffmpeg's %06d) would be a frame off.
  bool lines_by_file_number = true;
};

// The format of a ground-truth file, from its first data line: 12 numbers (kitti), 8 numbers separated by
// spaces (tum), 8 or more separated by commas (euroc). Throws OptionError ("format") when it is none of them.
GroundTruthFormat DetectGroundTruthFormat(const std::string& path);

// Reads a ground-truth file. `body_to_camera` (T_bc) turns EuRoC's body poses into camera poses; it is
// ignored by the other formats. Throws InputError naming the file and line when it is malformed.
GroundTruth ReadGroundTruth(const std::string& path, GroundTruthFormat format = GroundTruthFormat::kAuto,
                            const cv::Matx44d& body_to_camera = cv::Matx44d::eye());

// The ground truth that comes with an input: poses.txt in a KITTI sequence folder (or the official layout's
// poses/NN.txt beside sequences/NN), groundtruth.txt beside a TUM rgb.txt, an EuRoC sequence's
// state_groundtruth_estimate0/data.csv with its cam0/sensor.yaml. Nullopt when the input has none.
std::optional<GroundTruth> FindGroundTruth(const std::string& input_path, SourceFormat format);

// A ground-truth file the user gave (--gt): ReadGroundTruth, with EuRoC's body poses turned into cam0's by the T_BS of
// the cam0/sensor.yaml beside it (mav0/cam0 for mav0/state_groundtruth_estimate0/data.csv) or, where none is, of the
// input's (an EuRoC sequence); a warning where neither says it.
GroundTruth ReadGivenGroundTruth(const std::string& path, GroundTruthFormat format, const std::string& input_path,
                                 SourceFormat input_format);

// The camera-to-world pose of a key image: by its file's frame number or source_index (kitti), or by timestamp. Nullopt
// when the ground truth has no pose for it (past its end, no timestamp, or no pose within max_time_difference).
std::optional<cv::Matx44d> KeyImagePose(const GroundTruth& truth, const KeyImage& key, double max_time_difference);

// The relative pose from camera a to camera b given their camera-to-world poses: X_b = R X_a + t.
void RelativeFromCameraToWorld(const cv::Matx44d& T_wa, const cv::Matx44d& T_wb, cv::Matx33d* R, cv::Vec3d* t);

// Unit quaternion (w, x, y, z) to a rotation matrix; the quaternion is normalised first.
cv::Matx33d QuaternionToRotation(double w, double x, double y, double z);

}  // namespace vmap
