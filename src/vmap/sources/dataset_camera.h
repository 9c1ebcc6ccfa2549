#pragma once
// The camera intrinsics that come with an input, and the files that hold them.
//
// Looked up beside the input, by layout:
//   kitti   calib.txt in the sequence folder: K = the left 3x3 of P0 (P2 when the frames come from image_2/)
//   euroc   sensor.yaml beside cam0/data.csv: intrinsics [fu, fv, cu, cv], distortion_coefficients
//           (radial-tangential k1, k2, p1, p2), resolution [w, h]
//   tum     intrinsics.txt beside rgb.txt
//   images  intrinsics.txt in the image folder or in its parent (a sequence folder holding images/)
//   video   intrinsics.txt beside the video
// intrinsics.txt holds "name value" lines: fx, fy, cx, cy, optionally k1, k2, p1, p2, k3, width, height;
// '#' starts a comment.

#include <optional>
#include <string>

#include "vmap/geometry/camera.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// The layout OpenFrameSource would read `path` as (`requested` unless it is kAuto).
SourceFormat DetectSourceFormat(const std::string& path, SourceFormat requested = SourceFormat::kAuto);

// The calibration file that comes with an input of the given (detected) layout, or empty when there is none.
std::string FindCalibrationFile(const std::string& input_path, SourceFormat format);

// The camera that comes with an input, or nullopt when it has no calibration file. Throws InputError when
// the file exists but is malformed.
std::optional<Camera> FindDatasetCamera(const std::string& input_path, SourceFormat format);

// Reads a calibration file of any kind vmap knows: an OpenCV FileStorage file (.yaml, .yml, .json, .xml:
// camera_matrix, distortion_coefficients, image_width, image_height), an EuRoC sensor.yaml, a KITTI
// calib.txt (P0) or an intrinsics.txt. Throws InputError naming the file and what is wrong.
Camera ReadCameraFile(const std::string& path);

// An EuRoC sensor.yaml: the camera and T_BS, the sensor-to-body transform (X_body = T_BS X_sensor).
struct EurocSensor {
  Camera camera;
  cv::Matx44d T_BS = cv::Matx44d::eye();
};
EurocSensor ReadEurocSensor(const std::string& sensor_yaml);

// The camera a --camera value names: "fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]]" or a calibration file (as above).
Camera ParseCameraOption(const std::string& value);

}  // namespace vmap
