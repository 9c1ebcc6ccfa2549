#include "vmap/testing/synthetic_scene.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <random>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace vmap::testing {
namespace fs = std::filesystem;

namespace {

struct Plane {
  std::array<cv::Vec3d, 4> corners;  // world coordinates, in texture order (tl, tr, br, bl)
  cv::Mat texture;
};

// Random blobs, bars and speckle: plenty of corners for FAST, no repetitive pattern.
cv::Mat RandomTexture(cv::Size size, cv::RNG& rng) {
  cv::Mat texture(size, CV_8UC3, cv::Scalar::all(rng.uniform(60, 200)));
  const int shapes = size.area() / 400;
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Scalar color(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
    if (rng.uniform(0, 2) == 0) {
      cv::circle(texture, c, rng.uniform(3, 18), color, cv::FILLED, cv::LINE_AA);
    } else {
      const cv::Point d(rng.uniform(4, 30), rng.uniform(4, 30));
      cv::rectangle(texture, c, c + d, color, cv::FILLED);
    }
  }
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  return texture;
}

Plane FrontoParallel(double x0, double x1, double y0, double y1, double z, cv::Size texture_size, cv::RNG& rng) {
  return {{cv::Vec3d(x0, y0, z), cv::Vec3d(x1, y0, z), cv::Vec3d(x1, y1, z), cv::Vec3d(x0, y1, z)},
          RandomTexture(texture_size, rng)};
}

}  // namespace

SyntheticSequence RenderSyntheticSequence(const SyntheticOptions& options) {
  cv::RNG rng(options.seed);
  std::vector<Plane> planes;
  // A far wall, a floor-like slanted plane and boxes at several depths: a scene F can be estimated from.
  planes.push_back(FrontoParallel(-12, 16, -6, 6, 12.0, cv::Size(1400, 600), rng));
  planes.push_back({{cv::Vec3d(-8, 1.2, 2.0), cv::Vec3d(12, 1.2, 2.0), cv::Vec3d(12, 3.0, 12.0),
                     cv::Vec3d(-8, 3.0, 12.0)},
                    RandomTexture(cv::Size(1000, 500), rng)});
  for (int i = 0; i < 7; ++i) {
    const double x = -3.0 + 2.2 * i, z = 4.0 + 1.3 * (i % 3);
    planes.push_back(FrontoParallel(x, x + 1.2, -1.5 + 0.3 * (i % 2), 0.6, z, cv::Size(240, 240), rng));
  }
  std::sort(planes.begin(), planes.end(), [](const Plane& a, const Plane& b) {
    return a.corners[0][2] + a.corners[2][2] > b.corners[0][2] + b.corners[2][2];  // far first
  });

  SyntheticSequence sequence;
  const double f = 0.9 * options.size.width;
  sequence.K = cv::Matx33d(f, 0, (options.size.width - 1) / 2.0, 0, f, (options.size.height - 1) / 2.0, 0, 0, 1);
  for (int k = 0; k < options.num_frames; ++k) {
    const cv::Vec3d center(options.step * k, 0.0, 0.25 * options.step * k);
    cv::Matx33d R;
    cv::Rodrigues(cv::Vec3d(0, options.yaw_per_frame * k, 0), R);
    CameraPose pose{R, -(R * center)};
    cv::Mat frame(options.size, CV_8UC3, cv::Scalar(40, 40, 40));
    for (const Plane& plane : planes) {
      std::vector<cv::Point2f> projected;
      bool visible = true;
      for (const cv::Vec3d& X : plane.corners) {
        const cv::Vec3d x = sequence.K * (pose.R * X + pose.t);
        if (x[2] <= 0.1) visible = false;
        projected.emplace_back(static_cast<float>(x[0] / x[2]), static_cast<float>(x[1] / x[2]));
      }
      if (!visible) continue;
      const float w = static_cast<float>(plane.texture.cols - 1), h = static_cast<float>(plane.texture.rows - 1);
      const std::vector<cv::Point2f> source = {{0, 0}, {w, 0}, {w, h}, {0, h}};
      const cv::Mat H = cv::getPerspectiveTransform(source, projected);
      cv::Mat warped, mask;
      cv::warpPerspective(plane.texture, warped, H, options.size, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
      cv::warpPerspective(cv::Mat(plane.texture.size(), CV_8U, cv::Scalar(255)), mask, H, options.size,
                          cv::INTER_NEAREST, cv::BORDER_CONSTANT);
      warped.copyTo(frame, mask);
    }
    sequence.poses.push_back(pose);
    sequence.frames.push_back(frame);
  }
  return sequence;
}

cv::Matx33d TrueFundamental(const cv::Matx33d& K, const CameraPose& pose_i, const CameraPose& pose_j) {
  // Relative motion from camera i to camera j: x_j = R x_i + t.
  const cv::Matx33d R = pose_j.R * pose_i.R.t();
  const cv::Vec3d t = pose_j.t - R * pose_i.t;
  const cv::Matx33d tx(0, -t[2], t[1], t[2], 0, -t[0], -t[1], t[0], 0);
  const cv::Matx33d Kinv = K.inv();
  return Kinv.t() * tx * R * Kinv;
}

void WriteImageFolder(const SyntheticSequence& sequence, const fs::path& directory) {
  fs::create_directories(directory);
  for (size_t i = 0; i < sequence.frames.size(); ++i) {
    cv::imwrite((directory / ("frame_" + std::to_string(i + 1) + ".png")).string(), sequence.frames[i]);
  }
}

TempDir::TempDir() {
  std::string pattern = (fs::temp_directory_path() / "vmap_test_XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

void WritePngHeader(const fs::path& path, uint32_t width, uint32_t height) {
  std::string bytes("\x89PNG\r\n\x1A\n", 8);
  auto put = [&](uint32_t value) {
    for (int i = 0; i < 4; ++i) bytes += static_cast<char>(value >> (24 - 8 * i));
  };
  auto chunk = [&](const std::string& type, const std::string& data) {
    put(static_cast<uint32_t>(data.size()));
    const std::string body = type + data;
    bytes += body;
    uint32_t crc = 0xFFFFFFFFu;  // CRC-32 of the chunk's type and data, as PNG defines it
    for (unsigned char c : body) {
      crc ^= c;
      for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    put(~crc);
  };
  std::string header;
  for (uint32_t value : {width, height}) {
    for (int i = 0; i < 4; ++i) header += static_cast<char>(value >> (24 - 8 * i));
  }
  header += std::string("\x08\x00\x00\x00\x00", 5);  // 8 bits, grey, default compression, filter, interlace
  chunk("IHDR", header);
  chunk("IDAT", "");
  std::ofstream(path, std::ios::binary) << bytes;
}


fs::path SharedDir() {
#ifdef VMAP_SHARED_DIR
  const fs::path dir(VMAP_SHARED_DIR);
  if (fs::is_directory(dir / "data")) return fs::canonical(dir);
#endif
  return {};
}

int RunVmap(const std::string& arguments, std::string* output) {
#ifdef VMAP_BINARY
  const std::string command = std::string("'") + VMAP_BINARY + "' " + arguments + " 2>&1";
#else
  const std::string command = "vmap " + arguments + " 2>&1";
#endif
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  std::string text;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) text.append(buffer.data(), n);
  const int status = pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace vmap::testing
