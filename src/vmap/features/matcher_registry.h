#pragma once
// The matcher models vmap knows, by name, and matchers created by name. features/ knows matchers only through
// this registry: ORB registers in matcher_registry.cc; each deep model registers from its own folder
// (neural/<model>/<model>_registration.cc) and is created by the LibTorch plugin (matcher_plugin.h).
// Adding a model: docs/code-layout.md.

#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher.h"

namespace vmap {

// One model's options behind a small interface. Behind it is the model's own aggregate struct with
// documented defaults (TypedModelOptions<T>), which callers that know the model reach with As<T>().
class ModelOptions {
 public:
  virtual ~ModelOptions() = default;
  virtual const char* model() const = 0;  // the registered name
  virtual std::unique_ptr<ModelOptions> Clone() const = 0;
  virtual void VisitFields(OptionFieldVisitor& visitor) = 0;
  virtual void Check() const = 0;  // throws OptionError naming the bad field by its JSON key

  // {"type": model(), one key per field}.
  nlohmann::json ToJson() const;
  // Reads the fields `object` holds into these options: missing ones keep their values, keys no field has
  // are ignored (maps also record derived values, e.g. LoFTR's coarse_stride). A value of the wrong type is
  // an InputError naming `where` + the key.
  void FromJson(const nlohmann::json& object, const std::string& where);

  // The typed struct; T must be this model's options (checked: std::logic_error otherwise).
  template <typename T>
  const T& As() const {
    CheckType(T::kModelName);
    return *static_cast<const T*>(const_cast<ModelOptions*>(this)->TypedData());
  }
  template <typename T>
  T& As() {
    CheckType(T::kModelName);
    return *static_cast<T*>(TypedData());
  }

 protected:
  virtual void* TypedData() = 0;
  // Called after FromJson: a model may normalise what older maps recorded.
  virtual void AfterReading() {}

 private:
  void CheckType(const char* model_name) const {
    if (std::strcmp(model_name, model()) != 0) {
      throw std::logic_error(std::string("options of '") + model() + "' asked for as '" + model_name + "'");
    }
  }
};

// The options struct T of one model: `static constexpr const char* kModelName`, `void Check() const`,
// `void VisitFields(OptionFieldVisitor&)`, and optionally `void AfterReading()` (see ModelOptions).
template <typename T>
class TypedModelOptions final : public ModelOptions {
 public:
  explicit TypedModelOptions(T value = T{}) : value_(std::move(value)) {}
  const char* model() const override { return T::kModelName; }
  std::unique_ptr<ModelOptions> Clone() const override { return std::make_unique<TypedModelOptions>(value_); }
  void VisitFields(OptionFieldVisitor& visitor) override { value_.VisitFields(visitor); }
  void Check() const override { value_.Check(); }

 protected:
  void* TypedData() override { return &value_; }
  void AfterReading() override { CallAfterReading(value_, 0); }

 private:
  template <typename U>
  static auto CallAfterReading(U& value, int) -> decltype(value.AfterReading(), void()) {
    value.AfterReading();
  }
  template <typename U>
  static void CallAfterReading(U&, long) {}

  T value_;
};

// One registered matcher model.
struct MatcherModel {
  std::string name;     // --matcher NAME, map.json's options.matcher.type
  std::string summary;  // one line for --help and `vmap weights`
  // The threshold tau `vmap build` uses with this matcher when --tau is not given (see DefaultTau).
  double default_tau = 0.5;
  // Created by the LibTorch plugin (libvmap_torch.so), loaded the first time such a model is created.
  bool needs_torch = false;
  std::function<std::unique_ptr<ModelOptions>()> default_options;
  // Creates the matcher from this model's options; empty for a model the plugin creates.
  std::function<std::unique_ptr<Matcher>(const ModelOptions&)> create;

  // A model whose options struct is `Options` (its name is Options::kModelName).
  template <typename Options>
  static MatcherModel Of(std::string summary, double default_tau) {
    MatcherModel model;
    model.name = Options::kModelName;
    model.summary = std::move(summary);
    model.default_tau = default_tau;
    model.default_options = [] { return std::make_unique<TypedModelOptions<Options>>(); };
    return model;
  }
};

// Registers a model; used once per model, as a namespace-scope object in the model's registration file.
// A name registered twice is a programming error (std::logic_error at start-up).
struct MatcherModelRegistration {
  explicit MatcherModelRegistration(MatcherModel model);
};

// Every registered model: the built-in ones (ORB) first, then the others by name.
const std::vector<MatcherModel>& MatcherModels();
// Throws InputError listing the registered names when `name` is not one.
const MatcherModel& FindMatcherModel(const std::string& name);
// "orb, aliked, loftr or xfeat": the registered names for messages and --help.
std::string MatcherModelNames();

// The matcher to create and the options of every registered model (each model's defaults until set): the
// command line sets any model's options before it knows which --matcher was chosen.
class MatcherOptions {
 public:
  std::string type = "orb";  // a registered model name (MatcherModelNames)
  // An image file: the matcher extracts features only where it is not black (features/camera_mask.h); "" = none.
  std::string camera_mask;

  MatcherOptions();
  MatcherOptions(const MatcherOptions& other);
  MatcherOptions& operator=(const MatcherOptions& other);
  MatcherOptions(MatcherOptions&&) = default;
  MatcherOptions& operator=(MatcherOptions&&) = default;

  // The options of a registered model; throws InputError (listing the names) for an unknown one.
  ModelOptions& model(const std::string& name);
  const ModelOptions& model(const std::string& name) const;
  const ModelOptions& selected() const { return model(type); }
  // Typed: options.Of<LoftrMatcherOptions>().weights = ...
  template <typename T>
  T& Of() {
    return model(T::kModelName).template As<T>();
  }
  template <typename T>
  const T& Of() const {
    return model(T::kModelName).template As<T>();
  }

  // `type` as "matcher" (--matcher) and every registered model's options under its name, for the command line
  // and the Python module. Not a record: a map records its matcher as the matcher describes itself
  // (Matcher::DescribeOptionsJson).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field as "<model>.<key>" ("orb.num_features")
  // The files the selected matcher reads, which no output may replace: the camera mask and the model's weights
  // file, those given.
  std::vector<std::string> FilesRead() const;

 private:
  std::map<std::string, std::unique_ptr<ModelOptions>> models_;
};

// The threshold tau `vmap build` uses with this matcher when --tau is not given. S = verified / tentative
// means something else for each matcher: ALIKED's mutual matches with a similarity floor stay mostly inliers
// while their number collapses (docs/measurements/code-choices.md, "Default tau per matcher"), XFeat's keypoints
// fit F at 0.5 px less often than ORB's. Each value is the lowest tau of the sweeps in
// docs/measurements/deep-matchers.md whose maps keep >= 95 % usable links where ground truth exists, and a key
// image every few frames elsewhere. Throws InputError for an unknown type.
double DefaultTau(const std::string& matcher_type);

// Within options.camera_mask when one is given (WithCameraMask). Throws InputError when the matcher cannot be
// created (unknown type, a deep matcher without LibTorch, weights missing, a mask that cannot be read).
std::unique_ptr<Matcher> CreateMatcher(const MatcherOptions& options);

}  // namespace vmap
