#include "vmap/map/map_json_fields.h"

#include "vmap/core/error.h"

namespace vmap::internal {
using nlohmann::json;

[[noreturn]] void Malformed(const std::filesystem::path& file, const std::string& what) {
  throw InputError("malformed map '" + file.string() + "': " + what + "; rebuild the map with `vmap build`");
}

std::string ShortText(const json& value) {
  std::string text = value.dump();
  return text.size() > 40 ? text.substr(0, 37) + "..." : text;
}

cv::Size SizeField(const Fields& fields, const json& object, const std::string& where, const char* name) {
  const json* value = Fields::Find(object, name);
  if (!value) return {};
  const std::string field = Fields::Join(where, name);
  if (!value->is_array() || value->size() != 2) fields.Fail(field, "must be [width, height]");
  constexpr long kMaxSide = 1L << 20;
  return {static_cast<int>(fields.Integer((*value)[0], field + "[0]", 0, kMaxSide)),
          static_cast<int>(fields.Integer((*value)[1], field + "[1]", 0, kMaxSide))};
}

}  // namespace vmap::internal
