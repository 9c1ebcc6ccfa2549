#include "vmap/features/matcher_registry.h"

#include <algorithm>
#include <cctype>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/options_json.h"
#include "vmap/features/camera_mask.h"
#include "vmap/features/matcher_plugin.h"
#include "vmap/features/orb_matcher.h"

namespace vmap {
namespace {

std::vector<MatcherModel>& Registry() {
  static std::vector<MatcherModel> models;
  return models;
}

// ORB, the paper's matcher, registers here; the deep models from their folders under neural/.
const MatcherModelRegistration kOrb{[] {
  MatcherModel model = MatcherModel::Of<OrbMatcherOptions>(
      "ORB keypoints (OpenCV) with brute-force Hamming matching, the paper's matcher",
      0.5);  // the paper's tables' middle; docs/method.md
  model.create = [](const ModelOptions& options) { return CreateOrbMatcher(options.As<OrbMatcherOptions>()); };
  return model;
}()};

}  // namespace

nlohmann::json ModelOptions::ToJson() const {
  OptionsJsonWriter writer;
  Clone()->VisitFields(writer);  // visiting needs mutable fields; the copy keeps this const
  writer.record()["type"] = model();
  return writer.record();
}

void ModelOptions::FromJson(const nlohmann::json& object, const std::string& where) {
  OptionsJsonReader reader{JsonFieldReader(object, where)};
  VisitFields(reader);
  AfterReading();
}

MatcherModelRegistration::MatcherModelRegistration(MatcherModel model) {
  auto& models = Registry();
  const bool known = std::any_of(models.begin(), models.end(), [&](const auto& m) { return m.name == model.name; });
  if (known) throw std::logic_error("matcher model '" + model.name + "' registered twice");
  if (!model.default_options) throw std::logic_error("matcher model '" + model.name + "' has no options");
  models.push_back(std::move(model));
  std::stable_sort(models.begin(), models.end(), [](const MatcherModel& a, const MatcherModel& b) {
    if (a.needs_torch != b.needs_torch) return !a.needs_torch;
    return a.name < b.name;
  });
}

const std::vector<MatcherModel>& MatcherModels() { return Registry(); }

std::string MatcherModelNames() {
  const auto& models = MatcherModels();
  std::string names;
  for (size_t i = 0; i < models.size(); ++i) {
    if (i > 0) names += i + 1 == models.size() ? " or " : ", ";
    names += models[i].name;
  }
  return names;
}

const MatcherModel& FindMatcherModel(const std::string& name) {
  for (const auto& model : MatcherModels()) {
    if (model.name == name) return model;
  }
  throw InputError("unknown matcher '" + name + "'; use " + MatcherModelNames());
}

MatcherOptions::MatcherOptions() {
  for (const auto& model : MatcherModels()) models_.emplace(model.name, model.default_options());
}

MatcherOptions::MatcherOptions(const MatcherOptions& other) : type(other.type), camera_mask(other.camera_mask) {
  for (const auto& [name, options] : other.models_) models_.emplace(name, options->Clone());
}

MatcherOptions& MatcherOptions::operator=(const MatcherOptions& other) {
  if (this != &other) *this = MatcherOptions(other);
  return *this;
}

ModelOptions& MatcherOptions::model(const std::string& name) {
  const auto it = models_.find(name);
  if (it == models_.end()) FindMatcherModel(name);  // throws, listing the names
  if (it == models_.end()) throw std::logic_error("matcher '" + name + "' registered after these options were made");
  return *it->second;
}

const ModelOptions& MatcherOptions::model(const std::string& name) const {
  return const_cast<MatcherOptions*>(this)->model(name);
}

void MatcherOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Matcher and features (the flags of the --matcher chosen apply)");
  // "Feature matcher: orb, aliked, loftr or xfeat" and each model's summary on a line of its own.
  static const std::string help = [] {
    std::string text = "Feature matcher: " + MatcherModelNames();
    for (const auto& model : MatcherModels()) text += "\n  " + model.name + ": " + model.summary;
    return text;
  }();
  visitor.Visit(OptionField{"type", "--matcher", help.c_str()}.Named("matcher").NotRecorded(), type);
  // Not recorded as a path: a map keeps the mask itself (camera_mask.png) and the matcher's record its digest.
  visitor.Visit(OptionField{"camera_mask", "--camera-mask",
                            "An image of the frames' size, black where no features may be (COLMAP's camera mask): a "
                            "fisheye's dark rim, the robot's own body. A map keeps it and localizes within it"}
                    .NotRecorded(),
                camera_mask);
  // Every model's fields, as "<model>.<key>" (the paths Check() names); a flag several models share (--weights,
  // --device) sets the field of each, whichever matcher is chosen.
  for (const auto& model : MatcherModels()) visitor.VisitNested(model.name.c_str(), *models_.at(model.name));
}

std::vector<std::string> MatcherOptions::FilesRead() const {
  std::vector<std::string> files;
  if (!camera_mask.empty()) files.push_back(camera_mask);
  // Every deep model names its file "weights" (the plugin's options are known here only as JSON).
  const nlohmann::json model_options = selected().ToJson();
  if (const auto weights = model_options.find("weights");
      weights != model_options.end() && weights->is_string() && !weights->get<std::string>().empty()) {
    files.push_back(weights->get<std::string>());
  }
  return files;
}

void MatcherOptions::Check() const {
  // Named as the field is given ("--matcher" on the command line), as an enum flag's error is.
  const auto registered = [](const std::string& name) {
    const auto& models = MatcherModels();
    return std::any_of(models.begin(), models.end(), [&](const MatcherModel& model) { return model.name == name; });
  };
  if (!registered(type)) {
    std::string lower = type;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    throw OptionError("matcher", "'" + type + "' is unknown; " +
                                     (registered(lower) ? "matchers are named in lower case: use " + lower
                                                        : "use " + MatcherModelNames()));
  }
  // The options of every matcher, used or not: an absurd value (NaN, out of range) is a mistake either way.
  for (const auto& [name, options] : models_) CheckField(name, *options);
}

double DefaultTau(const std::string& matcher_type) { return FindMatcherModel(matcher_type).default_tau; }

std::unique_ptr<Matcher> CreateMatcher(const MatcherOptions& options) {
  options.Check();
  const MatcherModel& model = FindMatcherModel(options.type);
  // An option found wrong only now (a device the machine lacks) is named as Check() names it.
  std::unique_ptr<Matcher> matcher = NameOptionErrorsWithin(model.name, [&] {
    return model.create ? model.create(options.selected()) : CreatePluginMatcher(options.selected());
  });
  if (options.camera_mask.empty()) return matcher;
  return WithCameraMask(std::move(matcher), CameraMask::Read(options.camera_mask));
}

}  // namespace vmap
