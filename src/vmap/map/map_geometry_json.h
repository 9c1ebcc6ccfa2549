#pragma once
// The map.json fields of the camera and of each link's geometry (pose, parallax, homography test), kept
// apart from map_io.cc so that the map format's core stays small.

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "vmap/geometry/camera.h"
#include "vmap/map/visual_map.h"

namespace vmap {

// {"model": "PINHOLE", "width": 640, "height": 480, "params": [fx, fy, cx, cy], "origin": "..."}: COLMAP's
// model name and parameter order.
nlohmann::json CameraToJson(const Camera& camera);
// Throws InputError naming `file` and `where` when the object is malformed.
Camera CameraFromJson(const nlohmann::json& object, const std::string& file, const std::string& where);

// The conventions every number of a map obeys, written once at the top of map.json.
nlohmann::json MapConventionsJson();

// Adds "pose", "parallax_px", "parallax_rotation_removed", "homography_share" and "planar" to a link's object.
void AddLinkGeometryJson(const Link& link, nlohmann::json& object);
// Reads them back (absent fields keep their defaults: maps of schema version 1 have none).
void ReadLinkGeometryJson(const nlohmann::json& object, Link& link, const std::string& file, const std::string& where);

}  // namespace vmap
