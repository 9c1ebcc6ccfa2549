#include "vmap/core/json_fields.h"

#include <limits>
#include <utility>

namespace vmap {

JsonFieldReader::JsonFieldReader(const nlohmann::json& object, std::string where)
    : object_(object), where_(std::move(where)) {
  if (!object_.is_object()) {
    throw InputError(where_ + " is not a JSON object (it is " + std::string(object_.type_name()) + ")");
  }
}

const nlohmann::json* JsonFieldReader::Find(const char* key, bool (nlohmann::json::*fits)() const noexcept,
                                            const char* expected) const {
  const auto it = object_.find(key);
  if (it == object_.end() || it->is_null()) return nullptr;
  // nlohmann converts between numbers and bools silently; a recorded value of another kind is a mistake.
  if (!((*it).*fits)()) {
    throw InputError(Path(key) + " must be " + expected + " (it is " + std::string(it->type_name()) + ")");
  }
  return &*it;
}

void JsonFieldReader::Read(const char* key, double* value) const {
  if (const nlohmann::json* found = Find(key, &nlohmann::json::is_number, "a number")) *value = found->get<double>();
}

void JsonFieldReader::Read(const char* key, int* value) const {
  const nlohmann::json* found = Find(key, &nlohmann::json::is_number_integer, "an integer");
  if (!found) return;
  if (*found < std::numeric_limits<int>::min() || *found > std::numeric_limits<int>::max()) {
    throw InputError(Path(key) + " is out of range (" + found->dump() + ")");
  }
  *value = found->get<int>();
}

void JsonFieldReader::Read(const char* key, bool* value) const {
  if (const nlohmann::json* found = Find(key, &nlohmann::json::is_boolean, "true or false"))
    *value = found->get<bool>();
}

void JsonFieldReader::Read(const char* key, std::string* value) const { ReadString(key, value); }

void JsonFieldReader::Read(const char* key, std::vector<int>* value) const {
  const nlohmann::json* found = Find(key, &nlohmann::json::is_array, "an array of integers");
  if (!found) return;
  std::vector<int> values;
  for (const nlohmann::json& item : *found) {
    if (!item.is_number_integer() || item < std::numeric_limits<int>::min() || item > std::numeric_limits<int>::max()) {
      throw InputError(Path(key) + " must be an array of integers (it holds " + item.dump() + ")");
    }
    values.push_back(item.get<int>());
  }
  *value = std::move(values);
}

void JsonFieldReader::Read(const char* key, const EnumField& value) const {
  std::string name;
  if (!ReadString(key, &name)) return;
  if (!value.Set(name)) {
    throw InputError(Path(key) + " is '" + name + "', which this vmap does not know (it knows " + value.names() + ")");
  }
}

bool JsonFieldReader::ReadString(const char* key, std::string* value) const {
  const nlohmann::json* found = Find(key, &nlohmann::json::is_string, "a string");
  if (found) *value = found->get<std::string>();
  return found != nullptr;
}

JsonFieldReader JsonFieldReader::Object(const char* key) const {
  const nlohmann::json* found = Find(key, &nlohmann::json::is_object, "a JSON object");
  return JsonFieldReader(found ? *found : nlohmann::json::object(), Path(key));
}

}  // namespace vmap
