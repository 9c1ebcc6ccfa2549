#include "map_objects.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "vmap/core/error.h"
#include "vmap/map/map_geometry_json.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"

#include "argument_errors.h"
#include "bindings.h"
#include "gil_release.h"
#include "numpy_convert.h"

namespace py = pybind11;

namespace vmap::python {

namespace {

// One key image or link of a map, which it keeps alive.
struct KeyImageRef {
  std::shared_ptr<const MapHandle> handle;
  int index = 0;
  const KeyImage& key() const { return handle->map.key_images.at(index); }
};
struct LinkRef {
  std::shared_ptr<const MapHandle> handle;
  int index = 0;
  const Link& link() const { return handle->map.links.at(index); }
};

py::object JsonToPython(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

py::object NoneIfNegative(double value) { return value < 0 ? py::none() : py::cast(value); }

py::array_t<float> CorrespondenceArray(const Link& link) {
  py::array_t<float> array({static_cast<py::ssize_t>(link.correspondences.size()), py::ssize_t{4}});
  for (size_t i = 0; i < link.correspondences.size(); ++i) {
    const Correspondence& c = link.correspondences[i];
    float* row = array.mutable_data(i);
    row[0] = c.p0.x, row[1] = c.p0.y, row[2] = c.p1.x, row[3] = c.p1.y;
  }
  return array;
}

py::array_t<bool> InlierMask(const Link& link) {
  py::array_t<bool> mask(static_cast<py::ssize_t>(link.correspondences.size()));
  for (size_t i = 0; i < link.correspondences.size(); ++i) {
    mask.mutable_at(i) = static_cast<int>(i) < link.num_verified;
  }
  return mask;
}

cv::Mat ReadKeyImageWithoutGil(const KeyImageRef& ref, bool grayscale) {
  GilRelease release;
  ref.handle->CheckUnchanged();
  return ReadKeyImage(ref.handle->directory, ref.key(), grayscale, ref.handle->map.input.frame_size);
}

}  // namespace

bool MapHandle::Unchanged() const {
  // The folder by its inode (a Localizer adds its cache to it); map.json by its time too.
  return SameFile(IdentityOf(directory), folder_identity) && IdentityOf(directory / kMapFileName) == map_json_identity;
}

void MapHandle::CheckUnchanged() const {
  if (Unchanged()) return;
  throw InputError(
      fmt::format("the map '{}' was replaced or removed since vmap.read_map read it; read it again "
                  "with vmap.read_map",
                  directory.string()));
}

std::shared_ptr<MapHandle> ReadMapHandle(const std::filesystem::path& directory) {
  auto handle = std::make_shared<MapHandle>();
  // Absolute: key images read later, and a Localizer made from the map, find it after os.chdir.
  std::error_code ec;
  handle->directory = std::filesystem::absolute(directory, ec);
  if (ec) handle->directory = directory;
  GilRelease release;
  handle->folder_identity = IdentityOf(handle->directory);
  handle->map_json_identity = IdentityOf(handle->directory / kMapFileName);
  RecordedMap read = ReadRecordedMap(directory);
  handle->map = std::move(read.map);
  handle->options = std::move(read.options);
  // A map built into the folder while it was read: what was read may mix the two.
  handle->CheckUnchanged();
  return handle;
}

std::shared_ptr<MapHandle> ReadBuiltMapHandle(const std::filesystem::path& directory, const VisualMap& built) {
  const auto replaced = [&](const std::string& why) {
    return InputError(fmt::format(
        "the map built into '{}' was replaced or removed before build_map() could read it back ({}): another "
        "build into the same folder? give each build a folder of its own",
        directory.string(), why));
  };
  std::shared_ptr<MapHandle> handle;
  try {
    handle = ReadMapHandle(directory);
  } catch (const InputError& error) {
    throw replaced(error.what());
  }
  // Key images at other frames, or of another input: another build's map, committed after this one's.
  const auto frames = [](const VisualMap& map) {
    std::vector<std::pair<int, int>> indices;
    for (const KeyImage& key : map.key_images) indices.emplace_back(key.frame_index, key.source_index);
    return indices;
  };
  if (handle->map.input.path != built.input.path || frames(handle->map) != frames(built)) {
    throw replaced("its key images are not the ones built");
  }
  return handle;
}

std::filesystem::path MapDirectory(const py::object& map_or_path) {
  if (py::isinstance<MapHandle>(map_or_path)) {
    const MapHandle& handle = map_or_path.cast<const MapHandle&>();
    handle.CheckUnchanged();  // a Localizer of a Map reads the folder again: it must be the map the Map shows
    return handle.directory;
  }
  return std::filesystem::path(TextArgument(map_or_path, "map"));
}

namespace {

// Views of a map come from vmap.read_map only. pybind11's own __new__ would give an object with no C++ value
// behind it, which crashed the interpreter on first use; the objects vmap returns are made without __new__.
template <typename Class>
Class& MadeByReadMapOnly(Class&& bound, const char* name) {
  bound.def_static("__new__", [name](const py::args&, const py::kwargs&) -> py::object {
    throw py::type_error(std::string("vmap.") + name +
                         " objects come from vmap.read_map(...); they are not made directly");
  });
  return bound;
}

}  // namespace

void BindMapObjects(py::module_& m) {
  MadeByReadMapOnly(
      py::class_<KeyImageRef>(m, "KeyImage", "A key image of a map (map.json's key_images[index]).")
          .def_property_readonly("index", [](const KeyImageRef& k) { return k.index; })
          .def_property_readonly("frame_index", [](const KeyImageRef& k) { return k.key().frame_index; })
          .def_property_readonly("source_index", [](const KeyImageRef& k) { return k.key().source_index; })
          .def_property_readonly("timestamp", [](const KeyImageRef& k) { return NoneIfNegative(k.key().timestamp); })
          .def_property_readonly("source_name", [](const KeyImageRef& k) { return k.key().source_name; })
          .def_property_readonly("image_file", [](const KeyImageRef& k) { return k.key().image_file; })
          .def_property_readonly("num_features", [](const KeyImageRef& k) { return k.key().num_features; })
          .def_property_readonly("reason", [](const KeyImageRef& k) { return k.key().reason; })
          .def_property_readonly(
              "image", [](const KeyImageRef& k) { return ImageArray(ReadKeyImageWithoutGil(k, false)); },
              "The key image, HxWx3 BGR uint8 (decoded from its file on each access).")
          .def_property_readonly(
              "gray", [](const KeyImageRef& k) { return ImageArray(ReadKeyImageWithoutGil(k, true)); },
              "The key image in grey, HxW uint8, straight from the decoder as vmap's sources read frames.")
          .def("__repr__",
               [](const KeyImageRef& k) {
                 return fmt::format("<vmap.KeyImage {}: frame {}, {}>", k.index, k.key().frame_index, k.key().reason);
               }),
      "KeyImage");

  MadeByReadMapOnly(
      py::class_<LinkRef>(m, "Link", "A link between consecutive key images (map.json's links[index]).")
          .def_property_readonly("index", [](const LinkRef& l) { return l.index; })
          .def_property_readonly("from_key", [](const LinkRef& l) { return l.link().from_key; })
          .def_property_readonly("to_key", [](const LinkRef& l) { return l.link().to_key; })
          .def_property_readonly(
              "from_frame", [](const LinkRef& l) { return l.handle->map.key_images.at(l.link().from_key).frame_index; })
          .def_property_readonly(
              "to_frame", [](const LinkRef& l) { return l.handle->map.key_images.at(l.link().to_key).frame_index; })
          .def_property_readonly("below_tau", [](const LinkRef& l) { return l.link().below_tau; })
          .def_property_readonly("similarity", [](const LinkRef& l) { return l.link().similarity; })
          .def_property_readonly("tentative", [](const LinkRef& l) { return l.link().num_tentative; })
          .def_property_readonly("verified", [](const LinkRef& l) { return l.link().num_verified; })
          .def_property_readonly("num_tentative", [](const LinkRef& l) { return l.link().num_tentative; })
          .def_property_readonly("num_verified", [](const LinkRef& l) { return l.link().num_verified; })
          .def_property_readonly(
              "F", [](const LinkRef& l) { return MatrixArray(l.link().F, l.link().has_fundamental); },
              "3x3: x_to^T F x_from = 0 in pixels; None when matching failed")
          .def_property_readonly("has_pose", [](const LinkRef& l) { return l.link().has_pose; })
          .def_property_readonly(
              "R", [](const LinkRef& l) { return MatrixArray(l.link().R, l.link().has_pose); },
              "X_to = R X_from + t (with the map's camera); None without")
          .def_property_readonly("t", [](const LinkRef& l) { return VectorArray(l.link().t, l.link().has_pose); })
          .def_property_readonly("pose_inliers", [](const LinkRef& l) { return l.link().pose_inliers; })
          .def_property_readonly(
              "translation_known", [](const LinkRef& l) { return l.link().translation_known; },
              "t's direction is to be trusted; otherwise a robot gets the rotation only (False without a pose)")
          .def_property_readonly(
              "translation_sigma_deg", [](const LinkRef& l) { return NoneIfNegative(l.link().translation_sigma_deg); },
              "how well the matches determine t's direction, degrees; None when not computed")
          .def_property_readonly(
              "translation_rival_cost_gap",
              [](const LinkRef& l) { return NoneIfNegative(l.link().translation_rival_cost_gap); },
              "how much more the cheapest other minimum of the pose's cost costs; None when there is none")
          .def_property_readonly("parallax", [](const LinkRef& l) { return NoneIfNegative(l.link().parallax); })
          .def_property_readonly("parallax_without_rotation",
                                 [](const LinkRef& l) { return l.link().parallax_without_rotation; })
          .def_property_readonly("homography_share",
                                 [](const LinkRef& l) { return NoneIfNegative(l.link().homography_share); })
          .def_property_readonly("planar", [](const LinkRef& l) { return l.link().planar; })
          .def_property_readonly(
              "correspondences", [](const LinkRef& l) { return CorrespondenceArray(l.link()); },
              "N x 4 float32 (x0 y0 x1 y1), the verified ones first")
          .def_property_readonly(
              "inliers", [](const LinkRef& l) { return InlierMask(l.link()); },
              "N bools: the correspondence is an inlier of F")
          .def("__repr__",
               [](const LinkRef& l) {
                 return fmt::format("<vmap.Link {} -> {}: S {:.3f}, {} / {} verified{}>", l.link().from_key,
                                    l.link().to_key, l.link().similarity, l.link().num_verified, l.link().num_tentative,
                                    l.link().below_tau ? ", below tau" : "");
               }),
      "Link");

  MadeByReadMapOnly(
      py::class_<MapHandle, std::shared_ptr<MapHandle>>(m, "Map", "A map directory as vmap.read_map reads it.")
          .def_property_readonly("directory", [](const MapHandle& h) { return h.directory; })
          .def_property_readonly("key_images",
                                 [](const std::shared_ptr<MapHandle>& h) {
                                   std::vector<KeyImageRef> keys;
                                   for (size_t i = 0; i < h->map.key_images.size(); ++i) keys.push_back({h, int(i)});
                                   return keys;
                                 })
          .def_property_readonly("links",
                                 [](const std::shared_ptr<MapHandle>& h) {
                                   std::vector<LinkRef> links;
                                   for (size_t i = 0; i < h->map.links.size(); ++i) links.push_back({h, int(i)});
                                   return links;
                                 })
          .def_property_readonly(
              "quality", [](const MapHandle& h) { return h.map.quality; }, "Q of the paper")
          .def_property_readonly("num_frames", [](const MapHandle& h) { return h.map.num_frames; })
          .def_property_readonly("skipped_frames", [](const MapHandle& h) { return h.map.skipped_frames; })
          .def_property_readonly("seconds", [](const MapHandle& h) { return h.map.seconds; })
          .def_property_readonly(
              // py::object, not the accessor that ["input"] returns: it would outlive the dict it indexes.
              "input", [](const MapHandle& h) -> py::object { return JsonToPython(MapToJson(h.map))["input"]; },
              "map.json's input: path, format, native_size, frame_size, fps, camera")
          .def_property_readonly(
              "camera",
              [](const MapHandle& h) -> py::object {
                if (!h.map.input.camera) return py::none();
                return JsonToPython(CameraToJson(*h.map.input.camera).dump());
              },
              "The input's intrinsics as map.json records them; None without")
          .def_property_readonly(
              "camera_mask",
              [](const MapHandle& h) -> py::object {
                if (h.map.camera_mask.empty()) return py::none();
                return ImageArray(h.map.camera_mask);
              },
              "Where features may be found, HxW uint8 at the frames' size (0: none may be, 255: they may); None for a "
              "map built without --camera-mask")
          .def_property_readonly(
              "options", [](const MapHandle& h) { return JsonToPython(h.map.options_json); },
              "Every option that shaped the map, as map.json records them")
          .def_property_readonly("statistics",
                                 [](const MapHandle& h) {
                                   const MapStatistics s = ComputeStatistics(h.map, h.options.builder.quality_mean);
                                   py::dict d;
                                   d["num_frames"] = s.num_frames, d["num_key_images"] = s.num_key_images;
                                   d["min_verified"] = s.min_verified, d["max_verified"] = s.max_verified;
                                   d["mean_verified"] = s.mean_verified, d["mean_similarity"] = s.mean_similarity;
                                   d["quality"] = s.quality, d["below_tau_links"] = s.below_tau_links;
                                   return d;
                                 })
          .def_property_readonly(
              "json", [](const MapHandle& h) { return JsonToPython(MapToJson(h.map)); },
              "The whole map.json document as a dict")
          .def("__repr__",
               [](const MapHandle& h) {
                 return fmt::format("<vmap.Map '{}': {} frames, {} key images, Q {:.4f}>", h.directory.string(),
                                    h.map.num_frames, h.map.key_images.size(), h.map.quality);
               }),
      "Map");

  m.def(
      "read_map",
      [](const py::object& directory) {
        return ReadMapHandle(std::filesystem::path(TextArgument(directory, "read_map(): directory")));
      },
      py::arg("directory"), "Reads a map directory written by `vmap build` (or vmap.build_map).");
}

}  // namespace vmap::python
