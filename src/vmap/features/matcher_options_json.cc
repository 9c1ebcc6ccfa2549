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

void MatcherRunSettings::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"device", "--device",
                            "Deep matchers: where the map's matcher computes in this run, cpu or cuda (default: where "
                            "the map's did)"}
                    .HideDefault()
                    .NotRecorded(),
                device);
  visitor.Visit(OptionField{"weights", "--weights",
                            "Deep matchers: the weights file of the map's model this run reads (default: the map's; "
                            "see `vmap weights`)"}
                    .LocalFile()
                    .HideDefault()
                    .NotRecorded(),
                weights);
}

void MatcherRunSettings::Check() const {
  if (!device.empty() && device != "cpu" && device != "cuda") {
    throw OptionError("device", "'" + device + "' is not a device; use cpu or cuda");
  }
  std::error_code error;
  if (!weights.empty() && !std::filesystem::is_regular_file(weights, error)) {
    throw OptionError("weights", "'" + weights + "' is not a file; give the weights file of the map's model");
  }
}

MatcherOptions MatcherOptionsFromJson(const std::string& matcher_json, const std::string& map_file,
                                      const MatcherRunSettings& run) {
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
    if (std::string(field.key) == "weights" && !run.weights.empty()) return;  // the run's, set below
    value = DecodeFileName(value);
    if (std::filesystem::exists(value)) return;
    // A warning: the file found instead may hold other weights than the map was built with.
    spdlog::warn("the map's {} {} '{}' are not here; searching the weights directories", options.type, field.key,
                 value);
    value.clear();
  });
  model.VisitFields(forget_missing_files);
  bool has_device = false, has_weights = false;
  TextFields set_run([&](const OptionField& field, std::string& value) {
    const std::string key = field.key;
    if (key == "device" && !run.device.empty()) {
      value = run.device;
      has_device = true;
    }
    if (key == "weights" && field.is_local_file && !run.weights.empty()) {
      value = run.weights;
      has_weights = true;
    }
  });
  model.VisitFields(set_run);
  if (!run.device.empty() && !has_device && run.device != "cpu") {
    throw InputError("device " + run.device + ": the map's matcher " + options.type + " runs on the CPU only");
  }
  // Said, not refused: nothing is read, and a robot's weights parameter may stay set for a map of another matcher.
  if (!run.weights.empty() && !has_weights) {
    spdlog::warn("the weights '{}' are not read: the map's matcher {} reads none", run.weights, options.type);
  }
  options.Check();
  return options;
}

}  // namespace vmap
