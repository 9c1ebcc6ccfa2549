#include "vmap/evaluation/evaluation_inputs.h"

#include <filesystem>

#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/dataset_camera.h"

namespace vmap {
namespace fs = std::filesystem;

std::optional<Camera> ParseEvaluationCamera(const std::string& camera_option) {
  std::optional<Camera> camera;
  if (!camera_option.empty()) {
    // Checked even where the map's own camera is used, so that a wrong value is never silently passed over.
    std::error_code ec;
    if (fs::exists(camera_option, ec) && !fs::is_regular_file(camera_option, ec)) {
      throw OptionError("camera", "'" + camera_option +
                                      "' is not a regular file; give a calibration file or "
                                      "fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]]");
    }
    camera = ParseCameraOption(camera_option);
    try {
      camera->Check();
    } catch (const OptionError&) {
      throw;
    } catch (const InputError& error) {
      throw OptionError("camera", "'" + camera_option + "': " + error.what());
    }
  }
  return camera;
}

namespace {

// The map's input as found from here: its path as given where it names something from here, else the absolute path
// the map recorded where that does (a relative path is relative to the folder the map was built in); "" when neither.
std::string InputFromHere(const VisualMap& map) {
  std::error_code ec;
  for (const std::string& path : {map.input.path, map.input.absolute_path}) {
    if (!path.empty() && fs::exists(path, ec)) return path;
  }
  return "";
}

// Why the map's input cannot be looked into for what lies beside it (its ground truth, its calibration), or "".
std::string WhyInputUnreachable(const VisualMap& map) {
  if (map.input.path.empty()) return "the map records no input";
  if (InputFromHere(map).empty()) {
    return "the map's input '" + map.input.path + "' is not found from here" +
           (map.input.absolute_path.empty() ? std::string(" (a relative path is relative to the folder the map was "
                                                          "built in: run there)")
                                            : " nor at '" + map.input.absolute_path + "'");
  }
  return "";
}

}  // namespace

Camera EvaluationCamera(const VisualMap& map, const std::string& camera_option) {
  std::optional<Camera> camera = ParseEvaluationCamera(camera_option);
  if (map.input.camera) {
    if (camera) spdlog::warn("the map records its camera, which is used; --camera is for maps that have none");
    return *map.input.camera;
  }
  if (!camera) {
    if (const std::string unreachable = WhyInputUnreachable(map); !unreachable.empty()) {
      throw OptionError("camera", "is needed: the map has no camera and " + unreachable +
                                      "; give the intrinsics fx,fy,cx,cy (or a calibration file)");
    }
    camera = FindDatasetCamera(InputFromHere(map), map.input.format);
  }
  if (!camera) {
    throw OptionError("camera", "is needed: the map has no camera and its input '" + map.input.path +
                                    "' brings none; give the intrinsics fx,fy,cx,cy (or a calibration file)");
  }
  const cv::Size native = map.input.native_size.area() > 0 ? map.input.native_size : map.input.frame_size;
  const cv::Size frames = map.input.frame_size.area() > 0 ? map.input.frame_size : native;
  if (native.area() <= 0) throw InputError("the map does not record its frame size; rebuild it with `vmap build`");
  return CameraForFrames(*camera, native, frames);
}

GroundTruth MapGroundTruth(const VisualMap& map, const std::string& gt_path, GroundTruthFormat format) {
  if (!gt_path.empty()) {
    GroundTruth given = NameOptionErrorsWithin(
        "gt", [&] { return ReadGivenGroundTruth(gt_path, format, InputFromHere(map), map.input.format); });
    // KITTI poses of another input (an image folder): by position, unless the map does not say what its input was.
    given.lines_by_file_number = map.input.format == SourceFormat::kKitti || map.input.format == SourceFormat::kAuto;
    return given;
  }
  if (const std::string unreachable = WhyInputUnreachable(map); !unreachable.empty()) {
    throw OptionError("gt.path", "is needed: " + unreachable + "; or give a poses file");
  }
  std::optional<GroundTruth> truth = FindGroundTruth(InputFromHere(map), map.input.format);
  if (!truth) {
    throw OptionError("gt.path", "is needed: the map's input '" + map.input.path +
                                     "' has no ground truth beside it (KITTI poses.txt, TUM groundtruth.txt, EuRoC "
                                     "state_groundtruth_estimate0/data.csv); give a poses file");
  }
  return *truth;
}

}  // namespace vmap
