#include "vmap/map/map_geometry_json.h"

#include <cmath>

#include "vmap/core/error.h"

namespace vmap {
using nlohmann::json;

namespace {

[[noreturn]] void Malformed(const std::string& file, const std::string& what) {
  throw InputError("malformed map '" + file + "': " + what + "; rebuild the map with `vmap build`");
}

std::vector<double> Numbers(const json& value, size_t count, const std::string& file, const std::string& what) {
  if (!value.is_array() || value.size() != count) {
    Malformed(file, what + " must be a list of " + std::to_string(count) + " numbers");
  }
  std::vector<double> numbers;
  for (const json& item : value) {
    if (!item.is_number()) Malformed(file, what + " must be a list of " + std::to_string(count) + " numbers");
    numbers.push_back(item.get<double>());
    if (!std::isfinite(numbers.back())) Malformed(file, what + " holds a value that is not finite");
  }
  return numbers;
}

json OptionalNumber(double value) { return value < 0 ? json(nullptr) : json(value); }

void ReadLinkGeometryFields(const json& object, Link& link, const std::string& file, const std::string& where) {
  const auto pose = object.find("pose");
  if (pose != object.end() && !pose->is_null()) {
    if (!pose->is_object() || !pose->contains("R") || !pose->contains("t")) {
      Malformed(file, where + ".pose must be null or {R, t, inliers}");
    }
    const std::vector<double> R = Numbers((*pose)["R"], 9, file, where + ".pose.R");
    const std::vector<double> t = Numbers((*pose)["t"], 3, file, where + ".pose.t");
    for (int k = 0; k < 9; ++k) link.R(k / 3, k % 3) = R[k];
    link.t = cv::Vec3d(t[0], t[1], t[2]);
    // A rotation matrix and a unit vector, or the file was edited into nonsense.
    if (cv::norm(link.R * link.R.t() - cv::Matx33d::eye()) > 1e-3 || std::abs(cv::determinant(link.R) - 1.0) > 1e-3) {
      Malformed(file, where + ".pose.R is not a rotation matrix");
    }
    if (std::abs(cv::norm(link.t) - 1.0) > 1e-3) Malformed(file, where + ".pose.t is not a unit vector");
    link.pose_inliers = pose->value("inliers", 0);
    link.has_pose = true;
  }
  const auto number = [&](const char* name) -> double {
    const auto it = object.find(name);
    if (it == object.end() || it->is_null()) return -1.0;
    if (!it->is_number() || !std::isfinite(it->get<double>()) || it->get<double>() < 0) {
      Malformed(file, where + "." + name + " must be a number >= 0 or null");
    }
    return it->get<double>();
  };
  link.translation_sigma_deg = number("translation_sigma_deg");
  link.translation_rival_cost_gap = number("translation_rival_cost_gap");
  const auto known = object.find("translation_known");
  if (known != object.end() && !known->is_boolean())
    Malformed(file, where + ".translation_known must be true or false");
  link.translation_known = known == object.end() ? link.has_pose : known->get<bool>();
  if (link.translation_known && !link.has_pose) Malformed(file, where + ".translation_known is true without a pose");
  link.parallax = number("parallax_px");
  link.parallax_without_rotation = object.value("parallax_rotation_removed", false);
  link.homography_share = number("homography_share");
  link.planar = object.value("planar", false);
}

}  // namespace

json CameraToJson(const Camera& camera) {
  return {{"model", CameraModelName(camera.model)},
          {"width", camera.size.width},
          {"height", camera.size.height},
          {"params", camera.params()},
          {"origin", camera.origin}};
}

Camera CameraFromJson(const json& object, const std::string& file, const std::string& where) {
  if (!object.is_object()) Malformed(file, where + " must be an object");
  const auto model_it = object.find("model");
  if (model_it == object.end() || !model_it->is_string()) Malformed(file, where + " has no model name");
  CameraModel model;
  try {
    model = ParseCameraModel(model_it->get<std::string>());
  } catch (const InputError& e) {
    Malformed(file, where + ": " + e.what());
  }
  const auto params_it = object.find("params");
  if (params_it == object.end() || !params_it->is_array()) Malformed(file, where + " has no params");
  Camera camera;
  try {
    // Read wide, then bounded: 2^40 must not wrap around to a plausible int.
    const long width = object.value("width", 0L), height = object.value("height", 0L);
    if (width < 0 || height < 0 || width > kMaxCameraSide || height > kMaxCameraSide) {
      Malformed(file, where + " has the size " + std::to_string(width) + "x" + std::to_string(height) +
                          "; a side must be 0 to " + std::to_string(kMaxCameraSide) + " pixels");
    }
    camera = Camera::FromParams(model, Numbers(*params_it, params_it->size(), file, where + ".params"),
                                cv::Size(static_cast<int>(width), static_cast<int>(height)));
    camera.Check();  // before the origin: the message names the field, not where the camera came from
    camera.origin = object.value("origin", "");
  } catch (const InputError& e) {
    Malformed(file, where + ": " + e.what());
  } catch (const nlohmann::json::exception&) {
    Malformed(file, where + " has a field of the wrong type");
  }
  return camera;
}

json MapConventionsJson() {
  return {{"pixels", "pixel centres at integers (OpenCV): the top-left pixel's centre is (0, 0)"},
          {"F", "x_to^T F x_from = 0, pixels of the key images as stored (distortion not removed)"},
          {"pose", "X_to = R X_from + t (from the first key image's camera frame to the second's), |t| = 1"},
          {"camera_frame", "x right, y down, z forward (OpenCV)"}};
}

void AddLinkGeometryJson(const Link& link, json& object) {
  if (link.has_pose) {
    json R = json::array();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R.push_back(link.R(r, c));
    object["pose"] = {{"R", R}, {"t", {link.t[0], link.t[1], link.t[2]}}, {"inliers", link.pose_inliers}};
  } else {
    object["pose"] = nullptr;
  }
  object["translation_sigma_deg"] = OptionalNumber(link.translation_sigma_deg);
  object["translation_rival_cost_gap"] = OptionalNumber(link.translation_rival_cost_gap);
  object["translation_known"] = link.translation_known;
  object["parallax_px"] = OptionalNumber(link.parallax);
  object["parallax_rotation_removed"] = link.parallax_without_rotation;
  object["homography_share"] = OptionalNumber(link.homography_share);
  object["planar"] = link.planar;
}

void ReadLinkGeometryJson(const json& object, Link& link, const std::string& file, const std::string& where) {
  try {
    ReadLinkGeometryFields(object, link, file, where);
  } catch (const json::exception&) {
    Malformed(file, where + " has a pose, parallax or homography field of the wrong type");
  }
}

}  // namespace vmap
