#pragma once
// The camera of a sequence: a pinhole with optional Brown-Conrady (radial-tangential, optionally rational)
// distortion, or a fisheye lens with equidistant distortion, named as COLMAP names its camera models, so that a
// map's camera can be handed to COLMAP or read back from it.
//
// Conventions (OpenCV's, as everywhere in vmap):
//   pixel coordinates have pixel centres at integers: the top-left pixel's centre is (0, 0);
//   a point X in camera coordinates (x right, y down, z forward) projects to
//   (fx * x' + cx, fy * y' + cy) with (x', y') = distort(X.x / X.z, X.y / X.z);
//   distortion coefficients are in OpenCV's order k1, k2, p1, p2, k3, k4, k5, k6; a fisheye lens (OpenCV's
//   cv::fisheye, ROS's "equidistant") has k1..k4 of theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 +
//   k4 theta^8), where theta is the ray's angle to the optical axis, and no p1, p2.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"

namespace vmap {

// COLMAP's model names: SIMPLE_PINHOLE (f, cx, cy), PINHOLE (fx, fy, cx, cy),
// OPENCV (fx, fy, cx, cy, k1, k2, p1, p2), FULL_OPENCV (fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6),
// OPENCV_FISHEYE (fx, fy, cx, cy, k1, k2, k3, k4).
enum class CameraModel { kSimplePinhole, kPinhole, kOpenCV, kFullOpenCV, kOpenCVFisheye };
inline constexpr EnumName<CameraModel> kCameraModelNames[] = {{CameraModel::kSimplePinhole, "SIMPLE_PINHOLE"},
                                                              {CameraModel::kPinhole, "PINHOLE"},
                                                              {CameraModel::kOpenCV, "OPENCV"},
                                                              {CameraModel::kFullOpenCV, "FULL_OPENCV"},
                                                              {CameraModel::kOpenCVFisheye, "OPENCV_FISHEYE"}};

std::string CameraModelName(CameraModel model);
CameraModel ParseCameraModel(const std::string& name);  // COLMAP's names, as above

inline constexpr double kMaxCameraPixels = 1e7;  // focal lengths and principal point, pixels
inline constexpr double kMaxDistortion = 1e3;    // each distortion coefficient, in absolute value
inline constexpr int kMaxCameraSide = 1 << 20;   // the image size the intrinsics belong to, pixels

struct Camera {
  CameraModel model = CameraModel::kPinhole;
  cv::Size size;  // the image size the intrinsics belong to; empty when the calibration did not say
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0, k3 = 0.0;
  double k4 = 0.0, k5 = 0.0, k6 = 0.0;  // rational radial terms (FULL_OPENCV), or the fisheye's k4
  std::string origin;  // where the intrinsics came from (a file, or "--camera"), for messages and map.json

  cv::Matx33d K() const;
  bool is_fisheye() const { return model == CameraModel::kOpenCVFisheye; }
  // A fisheye lens always distorts: its zero coefficients are the equidistant projection, not a pinhole.
  bool has_distortion() const {
    return is_fisheye() || k1 != 0.0 || k2 != 0.0 || p1 != 0.0 || p2 != 0.0 || k3 != 0.0 || k4 != 0.0 || k5 != 0.0 ||
           k6 != 0.0;
  }
  // OpenCV's distortion vector (k1, k2, p1, p2[, k3[, k4, k5, k6]]), or cv::fisheye's (k1, k2, k3, k4); empty
  // without distortion.
  std::vector<double> distortion() const;

  // COLMAP's parameter list for `model`.
  std::vector<double> params() const;
  // The inverse of params(). Throws InputError when the count does not fit the model.
  static Camera FromParams(CameraModel model, const std::vector<double>& params, cv::Size size = {});
  // A camera from the numbers alone, with the simplest model that holds them (SIMPLE_PINHOLE when fx == fy and
  // there is no distortion, PINHOLE, OPENCV, FULL_OPENCV when k3..k6 are not all 0). `distortion` is OpenCV's
  // vector: 4, 5, 8 or more values (those past k6, thin-prism and tilt terms, must be 0).
  static Camera Make(double fx, double fy, double cx, double cy, const std::vector<double>& distortion = {},
                     cv::Size size = {});

  // The same camera for images resized to `new_size` (cv::resize maps pixel centres onto pixel centres:
  // x' = (x + 0.5) s - 0.5). Distortion is a function of normalised coordinates and does not change.
  // Needs `size` to be set.
  Camera ScaledTo(cv::Size new_size) const;

  // Throws InputError when a parameter cannot be right: non-finite values, focal lengths <= 0 or, like the
  // principal point, beyond kMaxCameraPixels, distortion coefficients beyond kMaxDistortion, a side of the size
  // beyond kMaxCameraSide. The one rule for every camera vmap takes in or writes (map.json, CameraInfo, --camera).
  void Check() const;
};

// "fx,fy,cx,cy" with optional distortion "fx,fy,cx,cy,k1,k2,p1,p2[,k3[,k4,k5,k6]]" (commas or spaces). Throws
// InputError.
Camera ParseCameraText(const std::string& text);

// An OpenCV FileStorage file (YAML, JSON or XML) as OpenCV's calibration tools write it: camera_matrix
// (3x3), distortion_coefficients (4, 5, 8... values; those past k6 must be zero), image_width and
// image_height (optional), and optionally distortion_model as ROS names it: plumb_bob or rational_polynomial
// (the default), equidistant or fisheye (4 coefficients k1..k4 of cv::fisheye). Throws InputError naming the
// file and what is missing.
Camera ReadOpenCvCameraFile(const std::string& path);

// The camera for frames of `frame_size` that were read at `native_size` (the input's own size) from a
// camera calibrated at `camera.size` (or at an unknown size, then assumed native): checks that the
// intrinsics fit the native size and scales them to the frame size. Throws InputError when they cannot fit
// (a calibration for another aspect ratio, or a principal point outside the image).
Camera CameraForFrames(const Camera& camera, cv::Size native_size, cv::Size frame_size);

// Pixel coordinates to normalised image coordinates (distortion removed, K^-1 applied): the rays
// (x, y, 1) in the camera frame.
std::vector<cv::Point2d> NormalizePoints(const Camera& camera, const std::vector<cv::Point2f>& pixels);
// Pixel coordinates with the distortion removed (K applied again): the pinhole image of the same rays.
std::vector<cv::Point2d> UndistortPixels(const Camera& camera, const std::vector<cv::Point2f>& pixels);

}  // namespace vmap
