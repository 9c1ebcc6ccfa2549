#include "vmap/cli/common_options.h"

#include <map>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <variant>
#include <vector>

namespace vmap::cli {

namespace {

// Collects every registered model's fields by flag, then binds each flag once: a flag several models share
// (--weights, --device) sets the field of each, whichever --matcher is chosen.
class FlagBinder final : public OptionFieldVisitor {
 public:
  void Visit(const OptionField& field, int& value) override { Add(field, &value); }
  void Visit(const OptionField& field, double& value) override { Add(field, &value); }
  void Visit(const OptionField& field, bool& value) override { Add(field, &value); }
  void Visit(const OptionField& field, std::string& value) override { Add(field, &value); }

  void Bind(CLI::App* command) const {
    for (const std::string& flag : order_) {
      const Targets& targets = flags_.at(flag);
      std::visit([&](auto* first) { BindTargets(command, flag, targets, first); }, targets.values.front());
    }
  }

 private:
  using Target = std::variant<int*, double*, bool*, std::string*>;
  struct Targets {
    OptionField field;
    std::vector<Target> values;
  };

  void Add(const OptionField& field, Target value) {
    if (*field.flag == '\0') return;
    auto [it, added] = flags_.try_emplace(field.flag, Targets{field, {}});
    if (added) order_.push_back(field.flag);
    if (it->second.values.size() > 0 && it->second.values.front().index() != value.index()) {
      throw std::logic_error(std::string("matcher flag ") + field.flag + " has fields of different types");
    }
    it->second.values.push_back(value);
  }

  template <typename T>
  static void BindTargets(CLI::App* command, const std::string& flag, const Targets& targets, T* first) {
    const OptionField& field = targets.field;
    if (flag.front() == '!') {  // "!--no-x": a bool flag that sets false
      if constexpr (std::is_same_v<T, bool>) {
        if (targets.values.size() == 1) {
          command->add_flag(flag, *first, field.help);
          return;
        }
      }
      throw std::logic_error("matcher flag " + flag + ": a negated flag needs exactly one bool field");
    }
    CLI::Option* option = nullptr;
    if (targets.values.size() == 1) {
      option = command->add_option(flag, *first, field.help);
      if (field.show_default) option->capture_default_str();
      return;
    }
    std::vector<T*> fields;
    for (const Target& target : targets.values) fields.push_back(std::get<T*>(target));
    option = command->add_option_function<T>(
        flag, [fields](const T& value) { for (T* f : fields) *f = value; }, field.help);
    if (field.show_default) {
      std::ostringstream text;
      text << std::boolalpha << *first;
      option->default_str(text.str());
    }
  }

  std::map<std::string, Targets> flags_;
  std::vector<std::string> order_;  // as the models list them
};

}  // namespace

void AddMatcherOptions(CLI::App* command, MatcherOptions& options) {
  std::string models;
  for (const auto& model : MatcherModels()) models += "\n  " + model.name + ": " + model.summary;
  command->add_option("--matcher", options.type, "Feature matcher: " + MatcherModelNames() + models)
      ->capture_default_str();
  // Every model's flags, as its options list them (features/option_fields.h).
  FlagBinder binder;
  for (const auto& model : MatcherModels()) options.model(model.name).VisitFields(binder);
  binder.Bind(command);
}

VerifierOptions VerifierFlags::Resolve() const {
  VerifierOptions resolved = options;
  resolved.method = ParseVerifierMethod(method);
  resolved.Check();
  return resolved;
}

void AddVerifierOptions(CLI::App* command, VerifierFlags& flags) {
  command
      ->add_option("--verifier", flags.method, "Fundamental matrix estimator: " + ListEnumNames(kVerifierMethodNames))
      ->capture_default_str();
  command->add_option("--threshold", flags.options.threshold, "Verifier inlier threshold in pixels")
      ->capture_default_str();
  command->add_option("--confidence", flags.options.confidence, "Verifier confidence")->capture_default_str();
  command->add_option("--max-iters", flags.options.max_iterations, "Verifier maximum iterations")
      ->capture_default_str();
  command->add_option("--seed", flags.options.seed, "Verifier random seed (same seed, same map)")
      ->capture_default_str();
}

FrameSourceOptions SourceFlags::Resolve() const {
  FrameSourceOptions resolved = options;
  resolved.format = ParseSourceFormat(format);
  resolved.Check();
  return resolved;
}

void AddSourceOptions(CLI::App* command, SourceFlags& flags) {
  command->add_option("--format", flags.format, "Input layout: " + ListEnumNames(kSourceFormatNames))
      ->capture_default_str();
  command->add_option("--first", flags.options.first, "First frame (0-based)")->capture_default_str();
  command->add_option("--last", flags.options.last, "Last frame, inclusive (-1 = end)")->capture_default_str();
  command->add_option("--stride", flags.options.stride, "Use every N-th frame")->capture_default_str();
  command->add_option("--resize", flags.options.resize, "Resize frames: WxH, or the longest side (e.g. 640)");
  command->add_flag("--strict", flags.options.strict, "Frames of a different size are an error, not a warning");
  command->add_option("--camera", flags.options.camera,
                      "Intrinsics: fx,fy,cx,cy[,k1,k2,p1,p2[,k3]] (pixels, native frame size) or a calibration file "
                      "(OpenCV YAML/JSON, EuRoC sensor.yaml, KITTI calib.txt, intrinsics.txt); 'none' ignores the "
                      "input's own. Default: the input's own, if any");
}

}  // namespace vmap::cli
