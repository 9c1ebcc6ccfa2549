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

// A unique empty temporary directory, removed by the destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The start of a PNG (signature, IHDR chunk, an empty IDAT chunk; CRCs included) announcing `width` x
// `height` grey pixels, with no image data: a decoder reads the size, then finds nothing to decode.
void WritePngHeader(const std::filesystem::path& path, uint32_t width, uint32_t height);

// The shared data folder (../shared), or empty when absent.
std::filesystem::path SharedDir();

// Runs the vmap binary with arguments (a shell command line), capturing stdout+stderr; returns the exit code.
int RunVmap(const std::string& arguments, std::string* output);

}  // namespace vmap::testing
