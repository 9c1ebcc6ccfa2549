#include "vmap/map/experiences.h"

#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/image_header.h"
#include "vmap/map/map_io.h"
#include "vmap/map/visual_map.h"

namespace vmap {
namespace fs = std::filesystem;
using nlohmann::json;

json ExperiencesToJson(const std::vector<Experience>& experiences) {
  json list = json::array();
  for (const Experience& e : experiences) {
    json views = json::array();
    for (const ExperienceView& v : e.views) {
      views.push_back({{"key", v.key},
                       {"image", EncodeFileName(v.image_file)},
                       {"frame_index", v.frame_index},
                       {"source_index", v.source_index},
                       {"timestamp", v.timestamp < 0 ? json(nullptr) : json(v.timestamp)},
                       {"source_name", EncodeFileName(v.source_name)},
                       {"heading_px", v.heading_px},
                       {"verified", v.num_verified}});
    }
    list.push_back({{"id", e.id}, {"source", EncodeFileName(e.source)}, {"views", std::move(views)}});
  }
  return list;
}

namespace {

// Checks one field after another, each failure naming it ("experiences[0].views[2].key").
class ViewReader {
 public:
  ViewReader(const fs::path& map_file) : map_file_(map_file) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    throw InputError("malformed map '" + map_file_.string() + "': '" + field + "' " + what +
                     "; remove the experience or rebuild the map with `vmap build`");
  }
  const json& Member(const json& object, const std::string& where, const char* name) const {
    if (!object.is_object()) Fail(where, "must be an object");
    const auto it = object.find(name);
    if (it == object.end()) Fail(where + "." + name, "is missing");
    return *it;
  }
  long Integer(const json& object, const std::string& where, const char* name, long low, long high) const {
    const json& value = Member(object, where, name);
    if (!value.is_number_integer() || value.get<std::int64_t>() < low || value.get<std::int64_t>() > high) {
      Fail(where + "." + name, "must be an integer from " + std::to_string(low) + " to " + std::to_string(high));
    }
    return static_cast<long>(value.get<std::int64_t>());
  }
  double Number(const json& object, const std::string& where, const char* name) const {
    const json& value = Member(object, where, name);
    if (!value.is_number() || !std::isfinite(value.get<double>())) Fail(where + "." + name, "must be a finite number");
    return value.get<double>();
  }
  std::string String(const json& object, const std::string& where, const char* name) const {
    const json& value = Member(object, where, name);
    if (!value.is_string()) Fail(where + "." + name, "must be a string");
    const std::string text = DecodeFileName(value.get<std::string>());
    if (text.find('\0') != std::string::npos) Fail(where + "." + name, "holds a NUL character");
    return text;
  }

 private:
  const fs::path& map_file_;
};

}  // namespace

std::vector<Experience> ExperiencesFromJson(const json& value, const VisualMap& map, const fs::path& directory,
                                            const fs::path& map_file) {
  const ViewReader reader(map_file);
  if (!value.is_array()) reader.Fail("experiences", "must be a list");
  constexpr long kMaxInt = std::numeric_limits<int>::max();
  const long num_keys = static_cast<long>(map.key_images.size());
  std::vector<Experience> experiences;
  for (size_t i = 0; i < value.size(); ++i) {
    const std::string where = "experiences[" + std::to_string(i) + "]";
    Experience e;
    e.id = static_cast<int>(reader.Integer(value[i], where, "id", 1, kMaxInt));
    if (e.id != static_cast<int>(i) + 1) reader.Fail(where + ".id", "must be " + std::to_string(i + 1));
    e.source = reader.String(value[i], where, "source");
    const json& views = reader.Member(value[i], where, "views");
    if (!views.is_array() || static_cast<long>(views.size()) > num_keys) {
      reader.Fail(where + ".views", "must be a list of at most one view per key image");
    }
    std::set<int> keys;
    for (size_t j = 0; j < views.size(); ++j) {
      const std::string at = where + ".views[" + std::to_string(j) + "]";
      ExperienceView v;
      v.key = static_cast<int>(reader.Integer(views[j], at, "key", 0, num_keys - 1));
      if (!keys.insert(v.key).second) reader.Fail(at + ".key", "names a key image that has a view already");
      v.frame_index = static_cast<int>(reader.Integer(views[j], at, "frame_index", 0, kMaxInt));
      v.source_index = static_cast<int>(reader.Integer(views[j], at, "source_index", 0, kMaxInt));
      const json& timestamp = reader.Member(views[j], at, "timestamp");
      v.timestamp = timestamp.is_null() ? -1.0 : reader.Number(views[j], at, "timestamp");
      if (!timestamp.is_null() && v.timestamp < 0) reader.Fail(at + ".timestamp", "must be null or >= 0");
      v.source_name = reader.String(views[j], at, "source_name");
      v.heading_px = reader.Number(views[j], at, "heading_px");
      // A heading is where the scene moved within the frame: one beyond its width (1e308) is damage, and would be
      // steered by.
      const int width = map.input.frame_size.width;
      if (width > 0 && !(std::abs(v.heading_px) <= width)) {
        reader.Fail(at + ".heading_px", fmt::format("{:g} is beyond the frames' width of {} px", v.heading_px, width));
      }
      v.num_verified = static_cast<int>(reader.Integer(views[j], at, "verified", 0, kMaxInt));
      v.image_file = reader.String(views[j], at, "image");
      if (!IsPlainRelativePath(v.image_file)) reader.Fail(at + ".image", "points outside the map directory");
      // As a key image: only the header is read, and it must be an image of the map's frame size.
      std::string why_not;
      const std::optional<ContainedFile> file = ContainedFile::Open(directory, v.image_file, &why_not);
      if (!file) reader.Fail(at + ".image", "'" + v.image_file + "' " + why_not);
      const std::optional<cv::Size> size = ImageHeaderSize(*file);
      const cv::Size expected = map.input.frame_size;
      if (!size || (expected.area() > 0 && *size != expected)) {
        reader.Fail(at + ".image", "'" + v.image_file + "' is not a PNG or JPEG of the map's frame size");
      }
      if (const char* cut = CutShortImage(*file)) reader.Fail(at + ".image", "'" + v.image_file + "' is " + cut);
      e.views.push_back(std::move(v));
    }
    experiences.push_back(std::move(e));
  }
  return experiences;
}

}  // namespace vmap
