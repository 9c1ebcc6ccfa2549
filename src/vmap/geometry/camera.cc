#include "vmap/geometry/camera.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/number_text.h"

namespace vmap {

std::string CameraModelName(CameraModel model) { return EnumToName(kCameraModelNames, model); }

CameraModel ParseCameraModel(const std::string& name) { return ParseEnum(kCameraModelNames, name, "camera model"); }

cv::Matx33d Camera::K() const { return cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1); }

std::vector<double> Camera::distortion() const {
  if (is_fisheye()) return {k1, k2, k3, k4};
  if (!has_distortion()) return {};
  if (k4 != 0.0 || k5 != 0.0 || k6 != 0.0) return {k1, k2, p1, p2, k3, k4, k5, k6};
  if (k3 != 0.0) return {k1, k2, p1, p2, k3};
  return {k1, k2, p1, p2};
}

std::vector<double> Camera::params() const {
  switch (model) {
    case CameraModel::kSimplePinhole:
      return {fx, cx, cy};
    case CameraModel::kPinhole:
      return {fx, fy, cx, cy};
    case CameraModel::kOpenCV:
      return {fx, fy, cx, cy, k1, k2, p1, p2};
    case CameraModel::kFullOpenCV:
      return {fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6};
    case CameraModel::kOpenCVFisheye:
      return {fx, fy, cx, cy, k1, k2, k3, k4};
  }
  return {};
}

Camera Camera::FromParams(CameraModel model, const std::vector<double>& params, cv::Size size) {
  static const size_t kCounts[] = {3, 4, 8, 12, 8};
  const size_t expected = kCounts[static_cast<int>(model)];
  if (params.size() != expected) {
    throw InputError(
        fmt::format("camera model {} has {} parameters, got {}", CameraModelName(model), expected, params.size()));
  }
  Camera camera;
  camera.model = model;
  camera.size = size;
  if (model == CameraModel::kSimplePinhole) {
    camera.fx = camera.fy = params[0];
    camera.cx = params[1];
    camera.cy = params[2];
    return camera;
  }
  camera.fx = params[0];
  camera.fy = params[1];
  camera.cx = params[2];
  camera.cy = params[3];
  if (model == CameraModel::kOpenCV || model == CameraModel::kFullOpenCV) {
    camera.k1 = params[4];
    camera.k2 = params[5];
    camera.p1 = params[6];
    camera.p2 = params[7];
  }
  if (model == CameraModel::kFullOpenCV) {
    camera.k3 = params[8];
    camera.k4 = params[9];
    camera.k5 = params[10];
    camera.k6 = params[11];
  }
  if (model == CameraModel::kOpenCVFisheye) {
    camera.k1 = params[4];
    camera.k2 = params[5];
    camera.k3 = params[6];
    camera.k4 = params[7];
  }
  return camera;
}

Camera Camera::Make(double fx, double fy, double cx, double cy, const std::vector<double>& distortion, cv::Size size) {
  Camera camera;
  camera.fx = fx;
  camera.fy = fy;
  camera.cx = cx;
  camera.cy = cy;
  camera.size = size;
  if (!distortion.empty() && distortion.size() < 4) {
    throw InputError("distortion needs k1, k2, p1, p2 (and optionally k3, or k3..k6)");
  }
  // OpenCV writes 5, 8, 12 or 14 coefficients; the thin-prism and tilt terms past k6 must be zero.
  for (size_t i = 8; i < distortion.size(); ++i) {
    if (distortion[i] != 0.0) {
      throw InputError(
          "distortion coefficients past k6 (thin-prism or tilt models) are not supported; "
          "recalibrate with OpenCV's default or rational model");
    }
  }
  if (distortion.size() == 6 || distortion.size() == 7) {
    throw InputError("distortion has " + std::to_string(distortion.size()) +
                     " coefficients; OpenCV's models have 4, 5, 8, 12 or 14");
  }
  double* const coefficients[] = {&camera.k1, &camera.k2, &camera.p1, &camera.p2,
                                  &camera.k3, &camera.k4, &camera.k5, &camera.k6};
  for (size_t i = 0; i < std::min<size_t>(distortion.size(), 8); ++i) *coefficients[i] = distortion[i];
  if (camera.k3 != 0.0 || camera.k4 != 0.0 || camera.k5 != 0.0 || camera.k6 != 0.0) {
    camera.model = CameraModel::kFullOpenCV;
  } else if (camera.has_distortion())
    camera.model = CameraModel::kOpenCV;
  else if (fx == fy)
    camera.model = CameraModel::kSimplePinhole;
  else
    camera.model = CameraModel::kPinhole;
  return camera;
}

Camera Camera::ScaledTo(cv::Size new_size) const {
  if (size.area() <= 0) throw std::logic_error("Camera::ScaledTo needs the calibration's image size");
  if (new_size == size) return *this;
  const double sx = static_cast<double>(new_size.width) / size.width;
  const double sy = static_cast<double>(new_size.height) / size.height;
  Camera scaled = *this;
  scaled.size = new_size;
  scaled.fx = fx * sx;
  scaled.fy = fy * sy;
  scaled.cx = (cx + 0.5) * sx - 0.5;
  scaled.cy = (cy + 0.5) * sy - 0.5;
  // fx == fy may no longer hold after an anisotropic resize.
  if (scaled.model == CameraModel::kSimplePinhole && scaled.fx != scaled.fy) scaled.model = CameraModel::kPinhole;
  return scaled;
}

void Camera::Check() const {
  const std::string where = origin.empty() ? "the camera" : "the camera from " + origin;
  for (double v : {fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6}) {
    if (!std::isfinite(v)) throw InputError(where + " has a parameter that is not a finite number");
  }
  if (!(fx > 0.0 && fy > 0.0)) {
    throw InputError(fmt::format("{} has focal lengths fx = {}, fy = {}; both must be > 0 (pixels)", where, fx, fy));
  }
  if (size.width < 0 || size.height < 0) throw InputError(where + " has a negative image size");
  if (size.width > kMaxCameraSide || size.height > kMaxCameraSide) {
    throw InputError(fmt::format("{} has the size {}x{}; a side must be 0 to {} pixels", where, size.width, size.height,
                                 kMaxCameraSide));
  }
  // No lens has a focal length or principal point of ten million pixels, nor distortion coefficients in the
  // thousands: such values come from a damaged or crafted calibration, and would overflow what is computed from
  // them (a map's reader refuses them too).
  if (fx > kMaxCameraPixels || fy > kMaxCameraPixels || std::abs(cx) > kMaxCameraPixels ||
      std::abs(cy) > kMaxCameraPixels) {
    throw InputError(where + " has a focal length or principal point beyond 10,000,000 pixels");
  }
  for (double k : {k1, k2, p1, p2, k3, k4, k5, k6}) {
    if (std::abs(k) > kMaxDistortion) throw InputError(where + " has a distortion coefficient beyond 1000");
  }
  if (is_fisheye() && (p1 != 0.0 || p2 != 0.0 || k5 != 0.0 || k6 != 0.0)) {
    throw InputError(where + " is a fisheye (OPENCV_FISHEYE) camera with p1, p2, k5 or k6 set; it has k1..k4 only");
  }
}

namespace {

std::vector<double> NumbersIn(const std::string& text) {
  std::string spaced = text;
  for (char& c : spaced) {
    if (c == ',' || c == ';') c = ' ';
  }
  std::istringstream in(spaced);
  std::vector<double> numbers;
  std::string token;
  while (in >> token) {
    const std::optional<double> number = ParseNumber(token);
    if (!number) {
      throw OptionError("camera", "'" + text + "': '" + token +
                                      "' is not a number; give fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]] or a "
                                      "calibration file");
    }
    numbers.push_back(*number);
  }
  return numbers;
}

// A matrix node as OpenCV writes it (!!opencv-matrix), as ROS's camera_calibration writes it ({rows, cols, data}),
// or a plain list of numbers.
std::vector<double> NodeNumbers(const cv::FileNode& node) {
  std::vector<double> values;
  if (node.empty() || node.isNone()) return values;
  if (node.isMap() && node["dt"].empty() && node["data"].isSeq()) {
    values = NodeNumbers(node["data"]);
    const cv::FileNode rows = node["rows"], cols = node["cols"];
    if (rows.isInt() && cols.isInt() &&
        static_cast<int>(rows) * static_cast<int>(cols) != static_cast<int>(values.size())) {
      throw InputError(fmt::format("a {}x{} matrix holds {} numbers", static_cast<int>(rows), static_cast<int>(cols),
                                   values.size()));
    }
    return values;
  }
  if (node.isMap()) {
    cv::Mat m;
    node >> m;
    m.convertTo(m, CV_64F);
    return std::vector<double>(m.begin<double>(), m.end<double>());
  }
  if (node.isSeq()) {
    for (const cv::FileNode& item : node) {
      if (item.isSeq()) {
        for (const cv::FileNode& inner : item) values.push_back(static_cast<double>(inner));
      } else {
        values.push_back(static_cast<double>(item));
      }
    }
    return values;
  }
  if (node.isReal() || node.isInt()) values.push_back(static_cast<double>(node));
  return values;
}

cv::FileNode FirstOf(const cv::FileStorage& fs, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    cv::FileNode node = fs[name];
    if (!node.empty() && !node.isNone()) return node;
  }
  return cv::FileNode();
}

}  // namespace

Camera ParseCameraText(const std::string& text) {
  const std::vector<double> n = NumbersIn(text);
  if (n.size() != 4 && n.size() != 8 && n.size() != 9 && n.size() != 12) {
    throw OptionError("camera", "'" + text + "' has " + std::to_string(n.size()) +
                                    " numbers; give fx,fy,cx,cy or fx,fy,cx,cy,k1,k2,p1,p2[,k3[,k4,k5,k6]] (pixels), "
                                    "or a calibration file");
  }
  Camera camera = Camera::Make(n[0], n[1], n[2], n[3], std::vector<double>(n.begin() + 4, n.end()));
  camera.origin = "--camera";
  camera.Check();
  return camera;
}

Camera ReadOpenCvCameraFile(const std::string& path) {
  static const std::string kFormats =
      "give OpenCV's calibration (camera_matrix, distortion_coefficients as !!opencv-matrix or lists), ROS "
      "camera_calibration's YAML (ost.yaml), COLMAP's cameras.txt, a TUM intrinsics.txt, a KITTI calib.txt or "
      "fx,fy,cx,cy";
  cv::FileStorage fs;
  try {
    // A YAML file without OpenCV's "%YAML:1.0" first line (ROS's ost.yaml, most hand-written ones) is read as one
    // with it: OpenCV's parser refuses it otherwise.
    std::string extension = std::filesystem::path(path).extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (extension == ".yaml" || extension == ".yml") {
      std::ifstream in(path, std::ios::binary);
      std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (text.rfind("%YAML", 0) != 0) text = "%YAML:1.0\n" + text;
      if (!fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY)) {
        throw InputError("cannot read camera file '" + path + "'");
      }
    } else if (!fs.open(path, cv::FileStorage::READ)) {
      throw InputError("cannot read camera file '" + path + "'");
    }
  } catch (const cv::Exception& e) {
    throw InputError("camera file '" + path + "' is not a YAML, JSON or XML file OpenCV reads (" + e.err + "); " +
                     kFormats);
  }
  std::vector<double> K, distortion;
  try {
    K = NodeNumbers(FirstOf(fs, {"camera_matrix", "cameraMatrix", "K"}));
    distortion = NodeNumbers(FirstOf(fs, {"distortion_coefficients", "dist_coeffs", "distCoeffs", "D"}));
  } catch (const cv::Exception& e) {
    throw InputError("camera file '" + path + "': camera_matrix or distortion_coefficients is malformed (" + e.err +
                     "); " + kFormats);
  } catch (const InputError& e) {
    throw InputError("camera file '" + path + "': camera_matrix or distortion_coefficients is malformed (" +
                     std::string(e.what()) + "); " + kFormats);
  }
  if (K.size() != 9) {
    throw InputError("camera file '" + path +
                     "' has no 3x3 camera_matrix (as OpenCV's calibration writes: camera_matrix, "
                     "distortion_coefficients, image_width, image_height)");
  }
  if (K[1] != 0.0 || K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 || K[8] != 1.0) {
    throw InputError("camera file '" + path + "': camera_matrix must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  }
  cv::Size size;
  const cv::FileNode width = fs["image_width"], height = fs["image_height"];
  if (width.isInt() && height.isInt()) size = cv::Size(static_cast<int>(width), static_cast<int>(height));
  const cv::FileNode model_node = fs["distortion_model"];
  const std::string model = model_node.isString() ? static_cast<std::string>(model_node) : "";
  Camera camera;
  if (model == "equidistant" || model == "fisheye") {
    if (distortion.size() != 4) {
      throw InputError("camera file '" + path + "': an " + model +
                       " camera needs 4 distortion_coefficients (k1..k4 "
                       "of cv::fisheye), got " +
                       std::to_string(distortion.size()));
    }
    camera =
        Camera::FromParams(CameraModel::kOpenCVFisheye,
                           {K[0], K[4], K[2], K[5], distortion[0], distortion[1], distortion[2], distortion[3]}, size);
  } else if (model.empty() || model == "plumb_bob" || model == "rational_polynomial" || model == "radtan") {
    camera = Camera::Make(K[0], K[4], K[2], K[5], distortion, size);
  } else {
    throw InputError("camera file '" + path + "': distortion_model '" + model +
                     "' is none of plumb_bob, rational_polynomial, equidistant, fisheye");
  }
  camera.origin = path;
  camera.Check();
  return camera;
}

Camera CameraForFrames(const Camera& camera, cv::Size native_size, cv::Size frame_size) {
  const std::string where = camera.origin.empty() ? "the camera" : "the camera from " + camera.origin;
  Camera native = camera;
  if (camera.size.area() > 0 && camera.size != native_size) {
    // A calibration at another resolution of the same sensor is usable when the aspect ratio is the same.
    const double ratio = static_cast<double>(camera.size.width) / camera.size.height;
    const double frame_ratio = static_cast<double>(native_size.width) / native_size.height;
    if (std::abs(ratio / frame_ratio - 1.0) > 0.01) {
      throw OptionError(
          "camera", fmt::format("must fit the frames: {} is for {}x{} images but the frames are "
                                "{}x{}; give a calibration of these frames",
                                where, camera.size.width, camera.size.height, native_size.width, native_size.height));
    }
    spdlog::info("{} is for {}x{} images; scaling it to the frames' {}x{}", where, camera.size.width,
                 camera.size.height, native_size.width, native_size.height);
    native = camera.ScaledTo(native_size);
  }
  native.size = native_size;
  if (!(native.cx > 0 && native.cx < native_size.width && native.cy > 0 && native.cy < native_size.height)) {
    throw OptionError("camera", fmt::format("must fit the frames: {} has its principal point ({:.1f}, {:.1f}) "
                                            "outside the {}x{} frames: it belongs to other images; give the right one",
                                            where, native.cx, native.cy, native_size.width, native_size.height));
  }
  if (std::abs(native.cx - 0.5 * native_size.width) > 0.2 * native_size.width ||
      std::abs(native.cy - 0.5 * native_size.height) > 0.2 * native_size.height) {
    spdlog::warn(
        "{} has its principal point ({:.1f}, {:.1f}) far from the centre of the {}x{} frames; check that "
        "it belongs to these images",
        where, native.cx, native.cy, native_size.width, native_size.height);
  }
  return native.ScaledTo(frame_size);
}

std::vector<cv::Point2d> NormalizePoints(const Camera& camera, const std::vector<cv::Point2f>& pixels) {
  std::vector<cv::Point2d> normalized;
  if (pixels.empty()) return normalized;
  if (!camera.has_distortion()) {
    normalized.reserve(pixels.size());
    for (const cv::Point2f& p : pixels)
      normalized.emplace_back((p.x - camera.cx) / camera.fx, (p.y - camera.cy) / camera.fy);
    return normalized;
  }
  std::vector<cv::Point2d> input(pixels.begin(), pixels.end());
  if (camera.is_fisheye()) {
    cv::fisheye::undistortPoints(input, normalized, cv::Mat(camera.K()), camera.distortion(), cv::noArray(),
                                 cv::noArray(),
                                 cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-10));
    return normalized;
  }
  // Iterative undistortion; OpenCV's default of 5 iterations leaves visible error at the image corners
  // of strongly distorted lenses.
  cv::undistortPoints(input, normalized, cv::Mat(camera.K()), camera.distortion(), cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-10));
  return normalized;
}

std::vector<cv::Point2d> UndistortPixels(const Camera& camera, const std::vector<cv::Point2f>& pixels) {
  if (!camera.has_distortion()) return std::vector<cv::Point2d>(pixels.begin(), pixels.end());
  std::vector<cv::Point2d> pinhole = NormalizePoints(camera, pixels);
  for (cv::Point2d& p : pinhole) p = cv::Point2d(camera.fx * p.x + camera.cx, camera.fy * p.y + camera.cy);
  return pinhole;
}

}  // namespace vmap
