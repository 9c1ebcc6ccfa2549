#pragma once
// An options struct's JSON record, written and read through its field list (core/option_fields.h): the one
// writer and the one reader of every "options" record vmap writes (map.json, sweep.json, eval.json, a
// localization run). Reading follows core/json_fields.h: a missing key keeps the field's value, an unknown key
// is ignored, a value of the wrong kind is an InputError naming its key's path.

#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/core/json_fields.h"
#include "vmap/core/option_fields.h"

namespace vmap {

class OptionsJsonWriter final : public OptionFieldVisitor {
 public:
  OptionsJsonWriter() : objects_{&record_} {}
  nlohmann::json& record() { return record_; }

 protected:
  void OnField(const OptionField& field, int& value) override { Write(field, value); }
  void OnField(const OptionField& field, double& value) override { Write(field, value); }
  void OnField(const OptionField& field, bool& value) override { Write(field, value); }
  void OnField(const OptionField& field, std::string& value) override;
  void OnField(const OptionField& field, std::vector<int>& value) override { Write(field, value); }
  void OnField(const OptionField& field, const EnumField& value) override { Write(field, value.name()); }
  void OnField(const OptionField& field, std::optional<double>& value) override {  // null when unset
    Write(field, value ? nlohmann::json(*value) : nlohmann::json(nullptr));
  }
  void OnEnter(const char* name, bool json_inline) override;
  void OnLeave(bool json_inline) override;

 private:
  template <typename T>
  void Write(const OptionField& field, const T& value) {
    if (field.recorded) (*objects_.back())[field.key] = value;
  }

  nlohmann::json record_ = nlohmann::json::object();
  std::vector<nlohmann::json*> objects_;  // the object being written, innermost last
};

class OptionsJsonReader final : public OptionFieldVisitor {
 public:
  explicit OptionsJsonReader(const JsonFieldReader& fields) : readers_{fields} {}

 protected:
  void OnField(const OptionField& field, int& value) override { Read(field, &value); }
  void OnField(const OptionField& field, double& value) override { Read(field, &value); }
  void OnField(const OptionField& field, bool& value) override { Read(field, &value); }
  void OnField(const OptionField& field, std::string& value) override;
  void OnField(const OptionField& field, std::vector<int>& value) override { Read(field, &value); }
  void OnField(const OptionField& field, const EnumField& value) override {
    if (field.recorded) readers_.back().Read(field.key, value);
  }
  void OnField(const OptionField& field, std::optional<double>& value) override;
  void OnEnter(const char* name, bool json_inline) override;
  void OnLeave(bool json_inline) override;

 private:
  template <typename T>
  void Read(const OptionField& field, T* value) {
    if (field.recorded) readers_.back().Read(field.key, value);
  }

  std::vector<JsonFieldReader> readers_;  // of the object being read, innermost last
};

// The record of `options` (any struct with VisitFields): one key per recorded field, nested structs as
// objects (or inline, as they ask).
template <typename Options>
nlohmann::json OptionsToJson(const Options& options) {
  Options copy = options;  // visiting hands out fields by reference
  OptionsJsonWriter writer;
  copy.VisitFields(writer);
  return writer.record();
}

// Reads a record written by OptionsToJson into `options`; fields it lacks keep their values.
template <typename Options>
void OptionsFromJson(const JsonFieldReader& fields, Options* options) {
  OptionsJsonReader reader(fields);
  options->VisitFields(reader);
}

}  // namespace vmap
