#include "vmap/testing/synthetic_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <random>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/simulation/plane_renderer.h"
#include "vmap/simulation/procedural_texture.h"

namespace vmap::testing {
namespace fs = std::filesystem;

namespace {

// A plane of the scene: world corners tl, tr, br, bl showing the whole texture.
TexturedPolygon FrontoParallel(double x0, double x1, double y0, double y1, double z, cv::Size texture_size,
                               cv::RNG& rng) {
  return TexturedQuad(cv::Vec3d(x0, y0, z), cv::Vec3d(x1, y0, z), cv::Vec3d(x1, y1, z), cv::Vec3d(x0, y1, z),
                      std::make_shared<Texture>(RandomTexture(texture_size, rng)));
}

}  // namespace

SyntheticSequence RenderSyntheticSequence(const SyntheticOptions& options) {
  cv::RNG rng(options.seed);
  std::vector<TexturedPolygon> planes;
  // A far wall, a floor-like slanted plane and boxes at several depths: a scene F can be estimated from.
  planes.push_back(FrontoParallel(-12, 16, -6, 6, 12.0, cv::Size(1400, 600), rng));
  planes.push_back(TexturedQuad(cv::Vec3d(-8, 1.2, 2.0), cv::Vec3d(12, 1.2, 2.0), cv::Vec3d(12, 3.0, 12.0),
                                cv::Vec3d(-8, 3.0, 12.0),
                                std::make_shared<Texture>(RandomTexture(cv::Size(1000, 500), rng))));
  for (int i = 0; i < 7; ++i) {
    const double x = -3.0 + 2.2 * i, z = 4.0 + 1.3 * (i % 3);
    planes.push_back(FrontoParallel(x, x + 1.2, -1.5 + 0.3 * (i % 2), 0.6, z, cv::Size(240, 240), rng));
  }

  SyntheticSequence sequence;
  const double f = 0.9 * options.size.width;
  sequence.K = cv::Matx33d(f, 0, (options.size.width - 1) / 2.0, 0, f, (options.size.height - 1) / 2.0, 0, 0, 1);
  // Far to near, as the planes were first drawn (the tests' expectations were measured on those images).
  std::stable_sort(planes.begin(), planes.end(), [](const TexturedPolygon& a, const TexturedPolygon& b) {
    return a.corners[0][2] + a.corners[2][2] > b.corners[0][2] + b.corners[2][2];
  });
  RenderOptions render;
  render.mipmaps = false;  // the textures are seen at about their size
  render.near = 0.1;
  render.legacy_synthetic = true;
  for (int k = 0; k < options.num_frames; ++k) {
    const cv::Vec3d center(options.step * k, 0.0, 0.25 * options.step * k);
    cv::Matx33d R;
    cv::Rodrigues(cv::Vec3d(0, options.yaw_per_frame * k, 0), R);
    CameraPose pose{R, -(R * center)};
    sequence.poses.push_back(pose);
    sequence.frames.push_back(RenderPolygons(planes, PinholeView{sequence.K, options.size, pose.R, pose.t}, render));
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

cv::Matx44d CameraToWorld(const CameraPose& pose) {
  const cv::Matx33d R_wc = pose.R.t();
  const cv::Vec3d t_wc = -(R_wc * pose.t);
  cv::Matx44d T = cv::Matx44d::eye();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T(r, c) = R_wc(r, c);
    T(r, 3) = t_wc[r];
  }
  return T;
}

namespace {

// Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method).
cv::Vec4d Quaternion(const cv::Matx44d& T) {
  const double trace = T(0, 0) + T(1, 1) + T(2, 2);
  double w, x, y, z;
  if (trace > 0) {
    const double s = 2.0 * std::sqrt(trace + 1.0);
    w = 0.25 * s;
    x = (T(2, 1) - T(1, 2)) / s;
    y = (T(0, 2) - T(2, 0)) / s;
    z = (T(1, 0) - T(0, 1)) / s;
  } else if (T(0, 0) > T(1, 1) && T(0, 0) > T(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + T(0, 0) - T(1, 1) - T(2, 2));
    w = (T(2, 1) - T(1, 2)) / s;
    x = 0.25 * s;
    y = (T(0, 1) + T(1, 0)) / s;
    z = (T(0, 2) + T(2, 0)) / s;
  } else if (T(1, 1) > T(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + T(1, 1) - T(0, 0) - T(2, 2));
    w = (T(0, 2) - T(2, 0)) / s;
    x = (T(0, 1) + T(1, 0)) / s;
    y = 0.25 * s;
    z = (T(1, 2) + T(2, 1)) / s;
  } else {
    const double s = 2.0 * std::sqrt(1.0 + T(2, 2) - T(0, 0) - T(1, 1));
    w = (T(1, 0) - T(0, 1)) / s;
    x = (T(0, 2) + T(2, 0)) / s;
    y = (T(1, 2) + T(2, 1)) / s;
    z = 0.25 * s;
  }
  return {w, x, y, z};
}

// The camera-to-world pose between frames k and k + 1 at fraction `a` (translation and rotation blended
// linearly: the steps are small).
cv::Matx44d PoseBetween(const SyntheticSequence& sequence, int k, double a) {
  const int next = std::min(k + 1, static_cast<int>(sequence.poses.size()) - 1);
  const cv::Matx44d A = CameraToWorld(sequence.poses[k]), B = CameraToWorld(sequence.poses[next]);
  cv::Matx33d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = (1 - a) * A(r, c) + a * B(r, c);
  cv::SVD svd(R);  // back onto the rotations
  R = cv::Matx33d(cv::Mat(svd.u * svd.vt));
  cv::Matx44d T = A;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T(r, c) = R(r, c);
    T(r, 3) = (1 - a) * A(r, 3) + a * B(r, 3);
  }
  return T;
}

std::ofstream OpenText(const fs::path& path) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path);
  out.precision(17);
  return out;
}

}  // namespace

void WriteKittiSequence(const SyntheticSequence& sequence, const fs::path& directory, double seconds_per_frame) {
  fs::create_directories(directory / "image_0");
  std::ofstream times = OpenText(directory / "times.txt"), poses = OpenText(directory / "poses.txt");
  for (size_t i = 0; i < sequence.frames.size(); ++i) {
    cv::Mat gray;
    cv::cvtColor(sequence.frames[i], gray, cv::COLOR_BGR2GRAY);
    cv::imwrite((directory / "image_0" / cv::format("%06zu.png", i)).string(), gray);
    times << i * seconds_per_frame << "\n";
    const cv::Matx44d T = CameraToWorld(sequence.poses[i]);
    for (int k = 0; k < 12; ++k) poses << T(k / 4, k % 4) << (k < 11 ? " " : "\n");
  }
  const cv::Matx33d& K = sequence.K;
  OpenText(directory / "calib.txt") << "P0: " << K(0, 0) << " 0 " << K(0, 2) << " 0 0 " << K(1, 1) << " " << K(1, 2)
                                    << " 0 0 0 1 0\n";
}

void WriteTumSequence(const SyntheticSequence& sequence, const fs::path& directory, double seconds_per_frame,
                      double gt_offset) {
  fs::create_directories(directory / "rgb");
  std::ofstream rgb = OpenText(directory / "rgb.txt"), truth = OpenText(directory / "groundtruth.txt");
  rgb << "# color images\n# timestamp filename\n";
  truth << "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n";
  const double base = 1305031102.0;  // TUM-like absolute timestamps
  for (size_t i = 0; i < sequence.frames.size(); ++i) {
    const std::string name = cv::format("rgb/%06zu.png", i);
    cv::imwrite((directory / name).string(), sequence.frames[i]);
    rgb << cv::format("%.6f", base + i * seconds_per_frame) << " " << name << "\n";
    // Two poses per frame: one `gt_offset` after it, and one half-way to the next frame.
    for (const double a : {gt_offset / seconds_per_frame, 0.5}) {
      const cv::Matx44d T = PoseBetween(sequence, static_cast<int>(i), a);
      const cv::Vec4d q = Quaternion(T);
      truth << cv::format("%.6f", base + (i + a) * seconds_per_frame) << " " << T(0, 3) << " " << T(1, 3) << " "
            << T(2, 3) << " " << q[1] << " " << q[2] << " " << q[3] << " " << q[0] << "\n";
    }
  }
  const cv::Matx33d& K = sequence.K;
  OpenText(directory / "intrinsics.txt") << "fx " << K(0, 0) << "\nfy " << K(1, 1) << "\ncx " << K(0, 2) << "\ncy "
                                         << K(1, 2) << "\n";
}

void WriteEurocSequence(const SyntheticSequence& sequence, const fs::path& directory, const cv::Matx44d& body_to_camera,
                        double seconds_per_frame) {
  const fs::path cam0 = directory / "mav0" / "cam0";
  fs::create_directories(cam0 / "data");
  std::ofstream csv = OpenText(cam0 / "data.csv");
  std::ofstream truth = OpenText(directory / "mav0" / "state_groundtruth_estimate0" / "data.csv");
  csv << "#timestamp [ns],filename\n";
  truth << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
           "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
           "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  const long long base = 1403636579758555392LL;
  const cv::Matx44d camera_to_body_inverse = body_to_camera.inv();
  for (size_t i = 0; i < sequence.frames.size(); ++i) {
    const long long ns = base + static_cast<long long>(std::llround(i * seconds_per_frame * 1e9));
    cv::Mat gray;
    cv::cvtColor(sequence.frames[i], gray, cv::COLOR_BGR2GRAY);
    cv::imwrite((cam0 / "data" / (std::to_string(ns) + ".png")).string(), gray);
    csv << ns << "," << ns << ".png\n";
    const cv::Matx44d T_wb = CameraToWorld(sequence.poses[i]) * camera_to_body_inverse;
    const cv::Vec4d q = Quaternion(T_wb);
    truth << ns << "," << T_wb(0, 3) << "," << T_wb(1, 3) << "," << T_wb(2, 3) << "," << q[0] << "," << q[1] << ","
          << q[2] << "," << q[3] << ",0,0,0,0,0,0,0,0,0\n";
  }
  std::ofstream yaml = OpenText(cam0 / "sensor.yaml");
  yaml << "%YAML:1.0\nsensor_type: camera\ncomment: synthetic\nT_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int k = 0; k < 16; ++k) yaml << body_to_camera(k / 4, k % 4) << (k < 15 ? ", " : "]\n");
  const cv::Matx33d& K = sequence.K;
  yaml << "rate_hz: 20\nresolution: [" << sequence.frames[0].cols << ", " << sequence.frames[0].rows
       << "]\ncamera_model: pinhole\nintrinsics: [" << K(0, 0) << ", " << K(1, 1) << ", " << K(0, 2) << ", " << K(1, 2)
       << "] #fu, fv, cu, cv\ndistortion_model: radial-tangential\ndistortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n";
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

}  // namespace vmap::testing
