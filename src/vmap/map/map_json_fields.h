#pragma once
// Typed, range-checked access to the fields of map.json (map/map_io.cc reads a map through it): every failure
// is an InputError that names the file and the field ("links[3].F") and says to rebuild the map. Internal to map/.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace vmap::internal {

// Throws the InputError of a malformed map: "malformed map 'FILE': WHAT; rebuild the map with `vmap build`".
[[noreturn]] void Malformed(const std::filesystem::path& file, const std::string& what);

// A JSON value as a short text for messages (at most 40 characters).
std::string ShortText(const nlohmann::json& value);

// Typed, range-checked access to map.json's fields: every failure names the field ("links[3].F").
class Fields {
 public:
  explicit Fields(const std::filesystem::path& file) : file_(file) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    Malformed(file_, "'" + field + "' " + what);
  }

  // The member, or null when absent.
  static const nlohmann::json* Find(const nlohmann::json& object, const char* name) {
    auto it = object.find(name);
    return it == object.end() ? nullptr : &*it;
  }

  const nlohmann::json& Required(const nlohmann::json& object, const std::string& where, const char* name) const {
    const nlohmann::json* value = Find(object, name);
    if (!value) Fail(Join(where, name), "is missing");
    return *value;
  }

  const nlohmann::json& Object(const nlohmann::json& value, const std::string& field) const {
    if (!value.is_object()) Fail(field, "must be an object");
    return value;
  }

  const nlohmann::json& Array(const nlohmann::json& value, const std::string& field) const {
    if (!value.is_array()) Fail(field, "must be a list");
    return value;
  }

  static bool IntegerIn(const nlohmann::json& value, long low, long high) {
    if (value.is_number_unsigned()) {
      const std::uint64_t number = value.get<std::uint64_t>();
      return high >= 0 && number <= static_cast<std::uint64_t>(high) &&
             (low <= 0 || number >= static_cast<std::uint64_t>(low));
    }
    if (!value.is_number_integer()) return false;
    const std::int64_t number = value.get<std::int64_t>();
    return number >= low && number <= high;
  }

  static bool NumberIn(const nlohmann::json& value, double low, double high) {
    if (!value.is_number()) return false;
    const double number = value.get<double>();
    return std::isfinite(number) && number >= low && number <= high;
  }

  long Integer(const nlohmann::json& value, const std::string& field, long low, long high) const {
    if (!IntegerIn(value, low, high)) {
      Fail(field, "must be an integer from " + std::to_string(low) + " to " + std::to_string(high) + " (got " +
                      ShortText(value) + ")");
    }
    return static_cast<long>(value.get<std::int64_t>());
  }

  double Number(const nlohmann::json& value, const std::string& field, double low, double high) const {
    if (!NumberIn(value, low, high)) {
      Fail(field, "must be a finite number from " + FormatNumber(low) + " to " + FormatNumber(high) + " (got " +
                      ShortText(value) + ")");
    }
    return value.get<double>();
  }

  std::string String(const nlohmann::json& value, const std::string& field) const {
    if (!value.is_string()) Fail(field, "must be a string");
    return value.get<std::string>();
  }

  bool Bool(const nlohmann::json& value, const std::string& field) const {
    if (!value.is_boolean()) Fail(field, "must be true or false");
    return value.get<bool>();
  }

  // Optional members: the default when absent.
  long Integer(const nlohmann::json& object, const std::string& where, const char* name, long low, long high,
               long absent) const {
    const nlohmann::json* value = Find(object, name);
    return value ? Integer(*value, Join(where, name), low, high) : absent;
  }
  double Number(const nlohmann::json& object, const std::string& where, const char* name, double low, double high,
                double absent) const {
    const nlohmann::json* value = Find(object, name);
    return value ? Number(*value, Join(where, name), low, high) : absent;
  }
  std::string String(const nlohmann::json& object, const std::string& where, const char* name) const {
    const nlohmann::json* value = Find(object, name);
    return value ? String(*value, Join(where, name)) : std::string();
  }

  static std::string Join(const std::string& where, const char* name) {
    return where.empty() ? std::string(name) : where + "." + name;
  }

 private:
  static std::string FormatNumber(double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  }

  const std::filesystem::path& file_;
};

// [width, height] of `object[name]`, each 0 to 2^20; an empty size when absent.
cv::Size SizeField(const Fields& fields, const nlohmann::json& object, const std::string& where, const char* name);

}  // namespace vmap::internal
