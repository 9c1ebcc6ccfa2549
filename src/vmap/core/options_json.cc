#include "vmap/core/options_json.h"

namespace vmap {

void OptionsJsonWriter::OnField(const OptionField& field, std::string& value) {
  if (field.omit_empty && value.empty()) return;
  Write(field, value.empty() && field.empty_as != nullptr ? std::string(field.empty_as) : value);
}

void OptionsJsonWriter::OnEnter(const char* name, bool json_inline) {
  nlohmann::json& holder = *objects_.back();
  if (json_inline) {
    objects_.push_back(&holder);
    return;
  }
  if (!holder.contains(name)) holder[name] = nlohmann::json::object();
  objects_.push_back(&holder[name]);
}

void OptionsJsonWriter::OnLeave(bool /*json_inline*/) { objects_.pop_back(); }

void OptionsJsonReader::OnField(const OptionField& field, std::string& value) {
  Read(field, &value);
  if (field.empty_as != nullptr && value == field.empty_as) value.clear();
}

void OptionsJsonReader::OnField(const OptionField& field, std::optional<double>& value) {
  if (!field.recorded) return;
  const nlohmann::json& object = readers_.back().object();
  if (object.contains(field.key) && object[field.key].is_null()) {
    value.reset();
    return;
  }
  double number = value.value_or(0.0);
  readers_.back().Read(field.key, &number);
  if (object.contains(field.key)) value = number;
}

void OptionsJsonReader::OnEnter(const char* name, bool json_inline) {
  readers_.push_back(json_inline ? readers_.back() : readers_.back().Object(name));
}

void OptionsJsonReader::OnLeave(bool /*json_inline*/) { readers_.pop_back(); }

}  // namespace vmap
