#include "vmap/sources/dataset_camera.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/folder_path.h"
#include "vmap/core/number_text.h"
#include "vmap/sources/internal.h"
#include "vmap/sources/recording_reader.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// A calibration file: a regular file (a FIFO would block) of at most 16 MB.
std::string ReadText(const std::string& path) {
  return ReadNamedFile(path, uint64_t{16} << 20, "calibration file", "give a calibration file");
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string StripComment(const std::string& line) {
  const auto hash = line.find('#');
  return hash == std::string::npos ? line : line.substr(0, hash);
}

// The numbers of `key: [a, b, ...]` in a simple YAML text (the list may span lines); empty when absent.
std::vector<double> YamlList(const std::string& text, const std::string& key, const std::string& file) {
  std::istringstream lines(text);
  std::string line, collected;
  bool inside = false;
  while (std::getline(lines, line)) {
    line = StripComment(line);
    if (!inside) {
      const auto colon = line.find(':');
      if (colon == std::string::npos) continue;
      std::string name = line.substr(0, colon);
      name.erase(0, name.find_first_not_of(" \t"));
      name.erase(name.find_last_not_of(" \t") + 1);
      if (name != key) continue;
      line = line.substr(colon + 1);
      inside = true;
    }
    collected += line + " ";
    if (line.find(']') != std::string::npos) break;
  }
  std::vector<double> numbers;
  if (!inside) return numbers;
  const auto open = collected.find('['), close = collected.find(']');
  if (open == std::string::npos || close == std::string::npos || close < open) {
    throw InputError("'" + file + "': '" + key + "' is not a [list] of numbers");
  }
  std::string body = collected.substr(open + 1, close - open - 1);
  std::replace(body.begin(), body.end(), ',', ' ');
  std::istringstream in(body);
  std::string token;
  while (in >> token) {
    const std::optional<double> number = ParseNumber(token);
    if (!number) throw InputError("'" + file + "': '" + key + "' holds '" + token + "', which is not a number");
    numbers.push_back(*number);
  }
  return numbers;
}

// The block `T_BS:` ... `data: [...]` of an EuRoC sensor.yaml.
std::vector<double> YamlMatrixData(const std::string& text, const std::string& key, const std::string& file) {
  const auto at = text.find(key + ":");
  if (at == std::string::npos) return {};
  return YamlList(text.substr(at + key.size() + 1), "data", file);
}

Camera ReadKittiCalib(const std::string& path, const std::string& projection) {
  std::istringstream lines(ReadText(path));
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string name;
    if (!(fields >> name) || name != projection + ":") continue;
    std::vector<double> P;
    std::string token;
    while (fields >> token) {
      const std::optional<double> v = ParseNumber(token);
      if (!v || !std::isfinite(*v)) {
        throw InputError("'" + path + "': " + projection + "'s value " + std::to_string(P.size() + 1) + ", '" +
                         token.substr(0, 40) + "', is not a finite number");
      }
      P.push_back(*v);
    }
    if (P.size() != 12) {
      throw InputError("'" + path + "': " + projection + " has " + std::to_string(P.size()) +
                       " numbers; a KITTI projection matrix has 12 (3x4, row-major)");
    }
    // P = K [I | t] for KITTI's rectified cameras: the left 3x3 is K.
    Camera camera = Camera::Make(P[0], P[5], P[2], P[6]);
    camera.origin = path;
    camera.Check();
    return camera;
  }
  throw InputError("'" + path + "' has no " + projection + ": line (KITTI calib.txt: P0: followed by 12 numbers)");
}

namespace {

// COLMAP's cameras.txt ("CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]", a camera a line): its first camera, or nullopt when
// the text is none (a first line whose second word is no model name, such as intrinsics.txt's "fx 525.0").
// COLMAP puts the centre of the top-left pixel at (0.5, 0.5), OpenCV and vmap at (0, 0): the principal point moves
// by half a pixel. SIMPLE_RADIAL and RADIAL are OpenCV's model with k1 (and k2) only.
std::optional<Camera> ReadColmapCameras(const std::string& path, const std::string& text) {
  static const std::map<std::string, size_t> kParameters = {{"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4}, {"SIMPLE_RADIAL", 4},
                                                            {"RADIAL", 5},         {"OPENCV", 8},  {"FULL_OPENCV", 12},
                                                            {"OPENCV_FISHEYE", 8}};
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    std::istringstream fields(StripComment(line));
    std::string id, model;
    if (!(fields >> id)) continue;
    if (!(fields >> model) || model.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZ_") != std::string::npos) {
      return std::nullopt;
    }
    const auto known = kParameters.find(model);
    if (known == kParameters.end()) {
      throw InputError(
          fmt::format("'{}' line {}: COLMAP camera model {} is not read; give SIMPLE_PINHOLE, PINHOLE, "
                      "SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV or OPENCV_FISHEYE",
                      path, number, model));
    }
    std::vector<double> values;
    for (std::string word; fields >> word;) {
      const std::optional<double> value = ParseNumber(word);
      if (!value) throw InputError(fmt::format("'{}' line {}: '{}' is not a number", path, number, word));
      values.push_back(*value);
    }
    if (values.size() != 2 + known->second) {
      throw InputError(fmt::format("'{}' line {}: a COLMAP {} camera is WIDTH HEIGHT and {} parameters, not {} numbers",
                                   path, number, model, known->second, values.size()));
    }
    const cv::Size size(static_cast<int>(values[0]), static_cast<int>(values[1]));
    std::vector<double> p(values.begin() + 2, values.end());
    const bool one_focal = model == "SIMPLE_PINHOLE" || model == "SIMPLE_RADIAL" || model == "RADIAL";
    const size_t cx = one_focal ? 1 : 2;
    p[cx] -= 0.5;
    p[cx + 1] -= 0.5;
    Camera camera;
    if (model == "SIMPLE_RADIAL" || model == "RADIAL") {
      camera = Camera::Make(p[0], p[0], p[1], p[2], {p[3], model == "RADIAL" ? p[4] : 0.0, 0.0, 0.0}, size);
    } else {
      camera = Camera::FromParams(ParseCameraModel(model), p, size);
    }
    camera.origin = path;
    camera.Check();
    return camera;
  }
  return std::nullopt;
}

}  // namespace

Camera ReadIntrinsicsText(const std::string& path) {
  std::istringstream lines(ReadText(path));
  std::map<std::string, double> values;
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    line = StripComment(line);
    std::replace(line.begin(), line.end(), ':', ' ');
    std::replace(line.begin(), line.end(), '=', ' ');
    std::istringstream fields(line);
    std::string name;
    if (!(fields >> name)) continue;
    std::string value_text;
    if (!(fields >> value_text)) {
      throw InputError(
          fmt::format("'{}' line {}: '{}' has no value; write 'name value' (e.g. fx 525.0)", path, number, name));
    }
    const std::optional<double> value = ParseNumber(value_text);
    if (!value) throw InputError(fmt::format("'{}' line {}: '{}' is not a number", path, number, value_text));
    values[Lower(name)] = *value;
  }
  if (values.count("f") && !values.count("fx")) values["fx"] = values["fy"] = values["f"];
  for (const char* required : {"fx", "fy", "cx", "cy"}) {
    if (!values.count(required)) {
      throw InputError("'" + path + "' has no '" + required +
                       "'; an intrinsics.txt needs fx, fy, cx, cy (pixels), optionally k1, k2, p1, p2, k3, width, "
                       "height");
    }
  }
  std::vector<double> distortion;
  if (values.count("k1") || values.count("k2") || values.count("p1") || values.count("p2") || values.count("k3")) {
    distortion = {values["k1"], values["k2"], values["p1"], values["p2"], values["k3"]};
  }
  cv::Size size;
  if (values.count("width") && values.count("height")) {
    size = cv::Size(static_cast<int>(values["width"]), static_cast<int>(values["height"]));
  }
  Camera camera = Camera::Make(values["fx"], values["fy"], values["cx"], values["cy"], distortion, size);
  camera.origin = path;
  camera.Check();
  return camera;
}

bool IsEurocSensorYaml(const std::string& text) {
  return text.find("intrinsics:") != std::string::npos && text.find("camera_model:") != std::string::npos;
}

EurocSensor ParseEurocSensor(const std::string& text, const std::string& path) {
  EurocSensor sensor;
  const std::vector<double> intrinsics = YamlList(text, "intrinsics", path);
  if (intrinsics.size() != 4) {
    throw InputError("'" + path + "': intrinsics must be [fu, fv, cu, cv] (EuRoC sensor.yaml)");
  }
  const auto model_at = text.find("camera_model:");
  if (model_at != std::string::npos) {
    std::istringstream model_line(text.substr(model_at + 13));
    std::string model;
    model_line >> model;
    if (model != "pinhole") {
      throw InputError("'" + path + "': camera_model '" + model + "' is not supported; vmap reads pinhole cameras");
    }
  }
  const auto distortion_model_at = text.find("distortion_model:");
  if (distortion_model_at != std::string::npos) {
    std::istringstream model_line(text.substr(distortion_model_at + 17));
    std::string model;
    model_line >> model;
    if (model != "radial-tangential" && model != "radtan" && model != "none") {
      throw InputError("'" + path + "': distortion_model '" + model +
                       "' is not supported; vmap reads radial-tangential (OpenCV's k1, k2, p1, p2)");
    }
  }
  const std::vector<double> distortion = YamlList(text, "distortion_coefficients", path);
  const std::vector<double> resolution = YamlList(text, "resolution", path);
  cv::Size size;
  if (resolution.size() == 2) size = cv::Size(static_cast<int>(resolution[0]), static_cast<int>(resolution[1]));
  sensor.camera = Camera::Make(intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3], distortion, size);
  sensor.camera.origin = path;
  sensor.camera.Check();
  const std::vector<double> T = YamlMatrixData(text, "T_BS", path);
  if (!T.empty()) {
    if (T.size() != 16) throw InputError("'" + path + "': T_BS data must hold 16 numbers (4x4, row-major)");
    for (int i = 0; i < 16; ++i) sensor.T_BS(i / 4, i % 4) = T[i];
  }
  return sensor;
}

}  // namespace

SourceFormat DetectSourceFormat(const std::string& path, SourceFormat requested) {
  if (requested != SourceFormat::kAuto) return requested;
  const fs::path p(path);
  if (IsRecording(path)) return SourceFormat::kRecording;
  if (fs::is_directory(p)) {
    if (fs::exists(p / "rgb.txt")) return SourceFormat::kTum;
    if (fs::exists(p / "mav0/cam0/data.csv") || fs::exists(p / "cam0/data.csv")) return SourceFormat::kEuroc;
    if (fs::is_directory(p / "image_0") || fs::is_directory(p / "image_2")) return SourceFormat::kKitti;
    return SourceFormat::kImageFolder;
  }
  if (p.filename() == "rgb.txt") return SourceFormat::kTum;
  if (p.filename() == "data.csv") return SourceFormat::kEuroc;
  return SourceFormat::kVideo;
}

std::string FindCalibrationFile(const std::string& input_path, SourceFormat format) {
  const fs::path p(input_path);
  // Whatever is there by that name: one that is no regular file (a FIFO, /dev/zero) is refused by the reader, not
  // taken for no calibration.
  const auto existing = [](const fs::path& candidate) {
    std::error_code ec;
    return fs::exists(fs::symlink_status(candidate, ec)) ? candidate.string() : std::string();
  };
  switch (format) {
    case SourceFormat::kKitti:
      return existing(p / "calib.txt");
    case SourceFormat::kEuroc: {
      fs::path csv = p;
      if (fs::is_directory(p))
        csv = fs::exists(p / "mav0/cam0/data.csv") ? p / "mav0/cam0/data.csv" : p / "cam0/data.csv";
      return existing(csv.parent_path() / "sensor.yaml");
    }
    case SourceFormat::kTum:
      return existing((fs::is_directory(p) ? p : p.parent_path()) / "intrinsics.txt");
    case SourceFormat::kImageFolder: {
      std::string found = existing(p / "intrinsics.txt");
      if (found.empty()) found = existing(NormalizedFolderPath(p).parent_path() / "intrinsics.txt");
      return found;
    }
    case SourceFormat::kVideo:
      return existing(p.parent_path() / "intrinsics.txt");
    case SourceFormat::kRecording:  // its camera is a topic of its own (recording_source.h)
    case SourceFormat::kAuto:
      break;
  }
  return {};
}

std::optional<Camera> FindDatasetCamera(const std::string& input_path, SourceFormat format) {
  format = DetectSourceFormat(input_path, format);
  const std::string file = FindCalibrationFile(input_path, format);
  if (file.empty()) return std::nullopt;
  if (format == SourceFormat::kKitti) {
    const bool left_colour = !fs::is_directory(fs::path(input_path) / "image_0");
    return ReadKittiCalib(file, left_colour ? "P2" : "P0");
  }
  return ReadCameraFile(file);
}

EurocSensor ReadEurocSensor(const std::string& sensor_yaml) {
  return ParseEurocSensor(ReadText(sensor_yaml), sensor_yaml);
}

Camera ReadCameraFile(const std::string& path) {
  // Refused as ReadText refuses a file (a FIFO would hang cv::FileStorage, which the other formats go to).
  std::string why_not;
  if (!ContainedFile::OpenRegular(path, &why_not)) {
    throw InputError("calibration file '" + path + "' " + why_not + "; give a calibration file");
  }
  const std::string extension = Lower(fs::path(path).extension().string());
  if (extension == ".yaml" || extension == ".yml") {
    const std::string text = ReadText(path);
    if (IsEurocSensorYaml(text)) return ParseEurocSensor(text, path).camera;
    return ReadOpenCvCameraFile(path);
  }
  if (extension == ".json" || extension == ".xml" || extension == ".gz") return ReadOpenCvCameraFile(path);
  const std::string text = ReadText(path);
  if (text.find("P0:") != std::string::npos) return ReadKittiCalib(path, "P0");
  if (std::optional<Camera> colmap = ReadColmapCameras(path, text)) return *colmap;
  return ReadIntrinsicsText(path);
}

Camera ParseCameraOption(const std::string& value) {
  // A name no file can have (too long) is not one: the value is then judged as numbers, and refused as the camera's.
  std::error_code not_a_file;
  if (fs::exists(value, not_a_file)) return ReadCameraFile(value);
  const bool looks_numeric = !value.empty() && value.find_first_not_of("0123456789.,;eE+- \t") == std::string::npos;
  if (!looks_numeric) {
    throw OptionError(
        "camera",
        "'" + value + "' is neither an existing calibration file nor fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]]");
  }
  return ParseCameraText(value);
}

}  // namespace vmap
