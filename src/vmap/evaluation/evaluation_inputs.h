#pragma once
// What a map is evaluated with (`vmap eval`, `vmap sweep --eval`): its camera and its ground truth, each the
// one given, else the one that comes with the map or its input.

#include <optional>
#include <string>

#include "vmap/evaluation/ground_truth.h"
#include "vmap/geometry/camera.h"
#include "vmap/map/visual_map.h"

namespace vmap {

// The camera to evaluate a map with: the map's own, else `camera_option`, else the one that comes with the
// map's input, scaled to the map's frame size. Throws OptionError ("camera") when there is none.
Camera EvaluationCamera(const VisualMap& map, const std::string& camera_option);
// The camera `camera_option` gives (nullopt when it is empty), checked: an OptionError for "camera" when it is
// neither a calibration file nor fx,fy,cx,cy[,...] of finite, positive focal lengths. EvaluationCamera calls it;
// a command calls it first, so that a wrong value is refused before anything else is read.
std::optional<Camera> ParseEvaluationCamera(const std::string& camera_option);

// The ground truth of a map: the file given (format from `format`, or detected), else the one that comes
// with the map's input. Throws OptionError ("gt.path" when there is none, "gt.format" when it cannot be told).
GroundTruth MapGroundTruth(const VisualMap& map, const std::string& gt_path, GroundTruthFormat format);

}  // namespace vmap
