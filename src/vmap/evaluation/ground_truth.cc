#include "vmap/evaluation/ground_truth.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/folder_path.h"
#include "vmap/core/number_text.h"
#include "vmap/sources/dataset_camera.h"
#include "vmap/sources/kitti_frame_number.h"

namespace vmap {
namespace fs = std::filesystem;

GroundTruthFormat ParseGroundTruthFormat(const std::string& name) {
  return ParseEnum(kGroundTruthFormatNames, name, "ground-truth format");
}

std::string GroundTruthFormatName(GroundTruthFormat format) { return EnumToName(kGroundTruthFormatNames, format); }

namespace {

bool IsDataLine(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first != std::string::npos && line[first] != '#' && line[first] != '%';
}

// The numbers of a line, separated by spaces, tabs or commas. Throws on a token that is not a number.
std::vector<double> LineNumbers(std::string line, const std::string& path, int number) {
  std::replace(line.begin(), line.end(), ',', ' ');
  std::istringstream in(line);
  std::vector<double> values;
  std::string token;
  while (in >> token) {
    const std::optional<double> value = ParseNumber(token);
    if (!value) throw InputError(fmt::format("ground truth '{}' line {}: '{}' is not a number", path, number, token));
    values.push_back(*value);
  }
  return values;
}

cv::Matx44d FromRotationTranslation(const cv::Matx33d& R, const cv::Vec3d& t) {
  cv::Matx44d T = cv::Matx44d::eye();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T(r, c) = R(r, c);
    T(r, 3) = t[r];
  }
  return T;
}

// KITTI prints its matrices to 6 or 7 digits, so their rotations are a rounding away from orthonormal; the
// nearest rotation (Frobenius norm, from the SVD) keeps that rounding out of the relative poses built from them.
cv::Matx44d WithNearestRotation(cv::Matx44d T) {
  cv::Matx33d u, vt;
  cv::Matx31d w;
  cv::SVD::compute(cv::Matx33d(T.get_minor<3, 3>(0, 0)), w, u, vt);
  const cv::Matx33d R = u * vt;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T(r, c) = R(r, c);
  }
  return T;
}

}  // namespace

cv::Matx33d QuaternionToRotation(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(n > 0)) return cv::Matx33d::eye();
  w /= n;
  x /= n;
  y /= n;
  z /= n;
  return cv::Matx33d(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),  //
                     2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),  //
                     2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y));
}

namespace {

// Ground truth positions lie within some thousand kilometres of their origin; 1e300 is damage, and its
// differences would be infinite or zero.
constexpr double kMaxPositionMetres = 1e7;

// Why a camera-to-world pose cannot be one (its rotation part not a rotation, a position beyond
// kMaxPositionMetres), or "". Files print poses to 6 digits or more: R^T R is I to within 1e-4 then.
std::string WhyNotAPose(const cv::Matx44d& T) {
  const cv::Matx33d R = T.get_minor<3, 3>(0, 0);
  const cv::Matx33d error = R.t() * R - cv::Matx33d::eye();
  double worst = 0.0;
  for (int i = 0; i < 9; ++i) worst = std::max(worst, std::abs(error.val[i]));
  if (!(worst <= 1e-2) || !(cv::determinant(R) > 0.0)) {
    return "its rotation is not a rotation matrix (R^T R - I reaches " + fmt::format("{:.3g}", worst) +
           ", det R = " + fmt::format("{:.3g}", cv::determinant(R)) + ")";
  }
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(T(i, 3)) <= kMaxPositionMetres)) return "its position lies beyond 10,000 km";
  }
  return "";
}

// The rotation of a unit quaternion; why not when it is not one (TUM and EuRoC print 4 or more decimals, so
// a norm far from 1 is a column out of place or damage).
std::string WhyNotAUnitQuaternion(double w, double x, double y, double z) {
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(std::abs(norm - 1.0) <= 1e-2)) return "its quaternion has norm " + fmt::format("{:.3g}", norm) + ", not 1";
  return "";
}

// A poses file of some hundred bytes a frame: 256 MB is far more than any sequence's. Read whole and at once,
// never line by line from the file itself, which a device such as /dev/zero would feed forever.
std::string ReadGroundTruthText(const std::string& path) {
  return ReadNamedFile(path, 256ull << 20, "ground truth",
                       "give a poses file (KITTI poses.txt, TUM groundtruth.txt or EuRoC data.csv)");
}

GroundTruthFormat DetectFormat(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!IsDataLine(line)) continue;
    const bool commas = line.find(',') != std::string::npos;
    size_t count = 0;
    try {
      count = LineNumbers(line, path, number).size();
    } catch (const InputError&) {
      break;  // not numbers: none of the formats
    }
    if (commas && count >= 8) return GroundTruthFormat::kEuroc;
    if (!commas && count == 12) return GroundTruthFormat::kKitti;
    if (!commas && count == 8) return GroundTruthFormat::kTum;
    break;
  }
  throw OptionError("format", "auto cannot tell the format of ground truth '" + path +
                                  "': its first line is not 12 numbers (KITTI poses.txt), 'timestamp tx ty tz qx qy qz "
                                  "qw' (TUM) or 'timestamp_ns,px,py,pz,qw,qx,qy,qz,...' (EuRoC); give the format");
}

// An EuRoC sequence's cam0 folder, from the input as given (the sequence, mav0/, or cam0/data.csv).
fs::path EurocCam0(const fs::path& input) {
  if (!fs::is_directory(input)) return input.parent_path();
  return fs::exists(input / "mav0/cam0") ? input / "mav0/cam0" : input / "cam0";
}

// Where cam0 sits on the body (T_BS of its sensor.yaml); nullopt where the folder has none.
std::optional<cv::Matx44d> EurocBodyToCamera(const fs::path& cam0) {
  if (!fs::is_regular_file(cam0 / "sensor.yaml")) return std::nullopt;
  return ReadEurocSensor((cam0 / "sensor.yaml").string()).T_BS;
}

}  // namespace

GroundTruthFormat DetectGroundTruthFormat(const std::string& path) {
  return DetectFormat(ReadGroundTruthText(path), path);
}

GroundTruth ReadGroundTruth(const std::string& path, GroundTruthFormat format, const cv::Matx44d& body_to_camera) {
  const std::string text = ReadGroundTruthText(path);
  if (format == GroundTruthFormat::kAuto) format = DetectFormat(text, path);
  std::istringstream in(text);
  GroundTruth truth;
  truth.path = path;
  truth.format = format;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!IsDataLine(line)) continue;
    const std::vector<double> v = LineNumbers(line, path, number);
    const auto bad = [&](const char* expected) {
      throw InputError(fmt::format("ground truth '{}' line {} has {} numbers; a {} line is {}", path, number, v.size(),
                                   GroundTruthFormatName(format), expected));
    };
    for (double value : v) {
      if (!std::isfinite(value)) throw InputError(fmt::format("ground truth '{}' line {}: not finite", path, number));
    }
    const auto check = [&](const std::string& why_not) {
      if (!why_not.empty()) {
        throw InputError(
            fmt::format("ground truth '{}' line {} is not a pose: {}; check that the file is a {} "
                        "poses file",
                        path, number, why_not, GroundTruthFormatName(format)));
      }
    };
    switch (format) {
      case GroundTruthFormat::kKitti: {
        if (v.size() != 12) bad("12 numbers (3x4 camera-to-world matrix, row-major)");
        cv::Matx44d T = cv::Matx44d::eye();
        for (int i = 0; i < 12; ++i) T(i / 4, i % 4) = v[i];
        check(WhyNotAPose(T));
        truth.camera_to_world.push_back(WithNearestRotation(T));
        break;
      }
      case GroundTruthFormat::kTum: {
        if (v.size() != 8) bad("'timestamp tx ty tz qx qy qz qw'");
        check(WhyNotAUnitQuaternion(v[7], v[4], v[5], v[6]));
        truth.timestamps.push_back(v[0]);
        truth.camera_to_world.push_back(
            FromRotationTranslation(QuaternionToRotation(v[7], v[4], v[5], v[6]), cv::Vec3d(v[1], v[2], v[3])));
        check(WhyNotAPose(truth.camera_to_world.back()));
        break;
      }
      case GroundTruthFormat::kEuroc: {
        if (v.size() < 8) bad("'timestamp_ns, px, py, pz, qw, qx, qy, qz, ...'");
        check(WhyNotAUnitQuaternion(v[4], v[5], v[6], v[7]));
        truth.timestamps.push_back(v[0] * 1e-9);
        const cv::Matx44d T_wb =
            FromRotationTranslation(QuaternionToRotation(v[4], v[5], v[6], v[7]), cv::Vec3d(v[1], v[2], v[3]));
        truth.camera_to_world.push_back(T_wb * body_to_camera);
        check(WhyNotAPose(truth.camera_to_world.back()));
        break;
      }
      case GroundTruthFormat::kAuto:
        break;
    }
  }
  if (truth.camera_to_world.empty()) throw InputError("ground truth '" + path + "' holds no poses");
  for (size_t i = 1; i < truth.timestamps.size(); ++i) {
    if (truth.timestamps[i] < truth.timestamps[i - 1]) {
      throw InputError("ground truth '" + path + "' is not sorted by time (line " + std::to_string(i + 1) +
                       " of its poses goes back); sort it");
    }
  }
  return truth;
}

std::optional<GroundTruth> FindGroundTruth(const std::string& input_path, SourceFormat format) {
  format = DetectSourceFormat(input_path, format);
  const fs::path p(input_path);
  switch (format) {
    case SourceFormat::kKitti: {
      if (fs::is_regular_file(p / "poses.txt"))
        return ReadGroundTruth((p / "poses.txt").string(), GroundTruthFormat::kKitti);
      // The official layout: dataset/sequences/07/ and dataset/poses/07.txt.
      const fs::path sequence = NormalizedFolderPath(p);
      const fs::path official =
          sequence.parent_path().parent_path() / "poses" / (sequence.filename().string() + ".txt");
      if (fs::is_regular_file(official)) return ReadGroundTruth(official.string(), GroundTruthFormat::kKitti);
      return std::nullopt;
    }
    case SourceFormat::kTum: {
      const fs::path file = (fs::is_directory(p) ? p : p.parent_path()) / "groundtruth.txt";
      if (fs::is_regular_file(file)) return ReadGroundTruth(file.string(), GroundTruthFormat::kTum);
      return std::nullopt;
    }
    case SourceFormat::kEuroc: {
      const fs::path cam0 = EurocCam0(p);
      const fs::path file = cam0.parent_path() / "state_groundtruth_estimate0" / "data.csv";
      if (!fs::is_regular_file(file)) return std::nullopt;
      return ReadGroundTruth(file.string(), GroundTruthFormat::kEuroc,
                             EurocBodyToCamera(cam0).value_or(cv::Matx44d::eye()));
    }
    default:
      return std::nullopt;
  }
}

GroundTruth ReadGivenGroundTruth(const std::string& path, GroundTruthFormat format, const std::string& input_path,
                                 SourceFormat input_format) {
  if (format == GroundTruthFormat::kAuto) format = DetectGroundTruthFormat(path);
  if (format != GroundTruthFormat::kEuroc) return ReadGroundTruth(path, format);
  // mav0/state_groundtruth_estimate0/data.csv: mav0/cam0/sensor.yaml lies beside it.
  std::optional<cv::Matx44d> body_to_camera =
      EurocBodyToCamera(NormalizedFolderPath(path).parent_path().parent_path() / "cam0");
  if (!body_to_camera && !input_path.empty() && input_format == SourceFormat::kEuroc) {
    body_to_camera = EurocBodyToCamera(EurocCam0(input_path));
  }
  if (!body_to_camera) {
    spdlog::warn(
        "the EuRoC ground truth '{}' gives the body's (IMU's) poses, and no cam0/sensor.yaml beside it or in the "
        "map's input says where the camera sits on the body (T_BS): the body's poses are taken as the camera's",
        path);
  }
  return ReadGroundTruth(path, format, body_to_camera.value_or(cv::Matx44d::eye()));
}

std::optional<cv::Matx44d> KeyImagePose(const GroundTruth& truth, const KeyImage& key, double max_time_difference) {
  if (truth.format == GroundTruthFormat::kKitti) {
    // By the image's own number where it is the frame's: the position in the listing is another frame's once an
    // image is missing.
    const int line =
        truth.lines_by_file_number ? KittiFrameNumber(key.source_name).value_or(key.source_index) : key.source_index;
    if (line < 0 || line >= static_cast<int>(truth.camera_to_world.size())) return std::nullopt;
    return truth.camera_to_world[line];
  }
  if (key.timestamp < 0 || truth.timestamps.empty()) return std::nullopt;
  const auto after = std::lower_bound(truth.timestamps.begin(), truth.timestamps.end(), key.timestamp);
  long best = -1;
  double best_difference = max_time_difference;
  for (auto it : {after, after == truth.timestamps.begin() ? after : after - 1}) {
    if (it == truth.timestamps.end()) continue;
    const double difference = std::abs(*it - key.timestamp);
    if (difference <= best_difference) {
      best_difference = difference;
      best = it - truth.timestamps.begin();
    }
  }
  if (best < 0) return std::nullopt;
  return truth.camera_to_world[best];
}

void RelativeFromCameraToWorld(const cv::Matx44d& T_wa, const cv::Matx44d& T_wb, cv::Matx33d* R, cv::Vec3d* t) {
  // X_w = R_a X_a + c_a = R_b X_b + c_b  =>  X_b = R_b^T R_a X_a + R_b^T (c_a - c_b).
  const cv::Matx33d R_a = T_wa.get_minor<3, 3>(0, 0), R_b = T_wb.get_minor<3, 3>(0, 0);
  const cv::Vec3d c_a(T_wa(0, 3), T_wa(1, 3), T_wa(2, 3)), c_b(T_wb(0, 3), T_wb(1, 3), T_wb(2, 3));
  *R = R_b.t() * R_a;
  *t = R_b.t() * (c_a - c_b);
}

}  // namespace vmap
