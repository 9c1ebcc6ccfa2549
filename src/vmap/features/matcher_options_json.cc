#include "vmap/features/matcher_options_json.h"

#include <filesystem>
#include <functional>
#include <utility>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"

namespace vmap {

namespace {

// Calls `visit` on each text field of a model's options (its weights file, its device).
class TextFields final : public OptionFieldVisitor {
 public:
  explicit TextFields(std::function<void(const OptionField&, std::string&)> visit) : visit_(std::move(visit)) {}

 protected:
  void OnField(const OptionField&, int&) override {}
  void OnField(const OptionField&, double&) override {}
  void OnField(const OptionField&, bool&) override {}
  void OnField(const OptionField&, std::vector<int>&) override {}
  void OnField(const OptionField&, const EnumField&) override {}
  void OnField(const OptionField& field, std::string& value) override { visit_(field, value); }

 private:
  std::function<void(const OptionField&, std::string&)> visit_;
};

}  // namespace

MatcherOptions MatcherOptionsFromJson(const std::string& matcher_json, const std::string& map_file,
                                      const std::string& device) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(matcher_json);
  } catch (const nlohmann::json::exception&) {
    throw InputError("map '" + map_file + "': options.matcher is not valid JSON; rebuild the map");
  }
  if (!doc.is_object() || !doc.contains("type") || !doc["type"].is_string()) {
    throw InputError("map '" + map_file +
                     "' does not record its matcher (options.matcher.type); rebuild it with "
                     "this vmap");
  }
  MatcherOptions options;
  options.type = doc["type"].get<std::string>();
  try {
    FindMatcherModel(options.type);
  } catch (const InputError&) {
    throw InputError("map '" + map_file + "' was built with the matcher '" + options.type +
                     "', which this vmap cannot create (it has " + MatcherModelNames() + "); use a vmap that has it");
  }
  ModelOptions& model = options.model(options.type);
  try {
    model.FromJson(doc, "options.matcher");
  } catch (const InputError& error) {
    throw InputError("map '" + map_file + "': " + error.what() + "; rebuild the map");
  }
  // The files a map recorded (weights), written percent-encoded (file_name_encoding.h), may not exist here: cleared,
  // the model then searches its weights directories.
  TextFields forget_missing_files([&](const OptionField& field, std::string& value) {
    if (!field.is_local_file || value.empty()) return;
    value = DecodeFileName(value);
    if (std::filesystem::exists(value)) return;
    // A warning: the file found instead may hold other weights than the map was built with.
    spdlog::warn("the map's {} {} '{}' are not here; searching the weights directories", options.type, field.key,
                 value);
    value.clear();
  });
  model.VisitFields(forget_missing_files);
  if (!device.empty()) {
    bool has_device = false;
    TextFields set_device([&](const OptionField& field, std::string& value) {
      if (std::string(field.key) != "device") return;
      value = device;
      has_device = true;
    });
    model.VisitFields(set_device);
    if (!has_device && device != "cpu") {
      throw InputError("device " + device + ": the map's matcher " + options.type + " runs on the CPU only");
    }
  }
  options.Check();
  return options;
}

}  // namespace vmap
