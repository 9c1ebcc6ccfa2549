#pragma once
// Synthetic sequences for tests: textured planes at several depths seen by a pinhole camera moving along
// a known path, so that the true fundamental matrix between any two frames is known.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap::testing {

struct CameraPose {
  cv::Matx33d R = cv::Matx33d::eye();  // world to camera: x_cam = R X + t
  cv::Vec3d t;
};

struct SyntheticSequence {
  cv::Matx33d K;
  std::vector<CameraPose> poses;
  std::vector<cv::Mat> frames;  // 8-bit BGR
};

struct SyntheticOptions {
  int num_frames = 60;
  cv::Size size = cv::Size(320, 240);
  double step = 0.04;          // metres per frame, sideways with some forward motion
  double yaw_per_frame = 0.0;  // radians per frame
  unsigned seed = 7;
};

SyntheticSequence RenderSyntheticSequence(const SyntheticOptions& options);

// F with x_j^T F x_i = 0 for pixel coordinates (pixel centres at integers).
cv::Matx33d TrueFundamental(const cv::Matx33d& K, const CameraPose& pose_i, const CameraPose& pose_j);

// Writes frames as frame_1.png ... frame_N.png (names that only sort right naturally).
void WriteImageFolder(const SyntheticSequence& sequence, const std::filesystem::path& directory);

// The camera-to-world pose T_wc (X_world = R_wc X_cam + t_wc) of a world-to-camera pose.
cv::Matx44d CameraToWorld(const CameraPose& pose);

// The sequence in a dataset layout, with its intrinsics and ground truth as the dataset stores them
// (see evaluation/ground_truth.h), frames at `seconds_per_frame`:
//   KITTI:  image_0/NNNNNN.png, times.txt, calib.txt (P0 = [K | 0]), poses.txt (camera-to-world, 3x4)
//   TUM:    rgb/NNNNNN.png, rgb.txt, intrinsics.txt, groundtruth.txt (camera-to-world, t q(x y z w)), the
//           ground truth sampled `gt_offset` seconds after each frame (and between frames, interpolated)
//   EuRoC:  mav0/cam0/data/<ns>.png, mav0/cam0/data.csv, mav0/cam0/sensor.yaml (intrinsics, T_BS = T_bc),
//           mav0/state_groundtruth_estimate0/data.csv (body poses T_wb = T_wc T_bc^-1, q(w x y z))
void WriteKittiSequence(const SyntheticSequence& sequence, const std::filesystem::path& directory,
                        double seconds_per_frame = 0.1);
void WriteTumSequence(const SyntheticSequence& sequence, const std::filesystem::path& directory,
                      double seconds_per_frame = 1.0 / 30, double gt_offset = 0.0);
void WriteEurocSequence(const SyntheticSequence& sequence, const std::filesystem::path& directory,
                        const cv::Matx44d& body_to_camera, double seconds_per_frame = 0.05);

// The start of a PNG (signature, IHDR chunk, an empty IDAT chunk; CRCs included) announcing `width` x
// `height` grey pixels, with no image data: a decoder reads the size, then finds nothing to decode.
void WritePngHeader(const std::filesystem::path& path, uint32_t width, uint32_t height);

}  // namespace vmap::testing
