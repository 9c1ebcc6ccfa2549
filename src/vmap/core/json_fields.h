#pragma once
// Reading an options record (map.json's "options", sweep.json's) back into the options structs, field by
// field. A record written by an older vmap lacks the fields added since and one written by a newer vmap has
// fields this one does not know: a missing (or null) key keeps the struct's value and an unknown key is
// ignored. A value of the wrong kind, or an enum name this vmap does not know, is an InputError that names
// the key by its path in the file ("options.verifier.threshold").

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/core/option_fields.h"

namespace vmap {

class JsonFieldReader {
 public:
  // `where` is the object's path, e.g. "options" or "map 'a/map.json': options". Throws InputError when
  // `object` is not a JSON object.
  JsonFieldReader(const nlohmann::json& object, std::string where);

  void Read(const char* key, double* value) const;
  void Read(const char* key, int* value) const;
  void Read(const char* key, bool* value) const;
  void Read(const char* key, std::string* value) const;
  void Read(const char* key, std::vector<int>* value) const;

  // An enum recorded by its name.
  void Read(const char* key, const EnumField& value) const;

  // The object under `key`; an empty one when the record lacks it (every field then keeps its value).
  JsonFieldReader Object(const char* key) const;

  const nlohmann::json& object() const { return object_; }
  std::string Path(const char* key) const { return where_ + "." + key; }

 private:
  // The value under `key` if present and not null; InputError if it is not of the kind `fits` accepts.
  const nlohmann::json* Find(const char* key, bool (nlohmann::json::*fits)() const noexcept,
                             const char* expected) const;
  bool ReadString(const char* key, std::string* value) const;

  nlohmann::json object_;
  std::string where_;
};

}  // namespace vmap
