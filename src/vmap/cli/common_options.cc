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
// (--weights, --device) sets the field of each, whichever --matcher is chosen. Each field is recorded as
// "<model>.<key>", the path MatcherOptions::Check() names.
class FlagBinder final : public OptionFieldVisitor {
 public:
  void VisitModel(const std::string& name, ModelOptions& options) {
    model_ = name;
    options.VisitFields(*this);
  }
  void Visit(const OptionField& field, int& value) override { Add(field, &value); }
  void Visit(const OptionField& field, double& value) override { Add(field, &value); }
  void Visit(const OptionField& field, bool& value) override { Add(field, &value); }
  void Visit(const OptionField& field, std::string& value) override { Add(field, &value); }

  void Bind(CLI::App* command, OptionFlags& option_flags) const {
    for (const std::string& flag : order_) {
      const Targets& targets = flags_.at(flag);
      CLI::Option* option = std::visit([&](auto* first) { return BindTargets(command, flag, targets, first); },
                                       targets.values.front());
      for (const std::string& path : targets.paths) option_flags.Record(path, option);
    }
  }

 private:
  using Target = std::variant<int*, double*, bool*, std::string*>;
  struct Targets {
    OptionField field;
    std::vector<Target> values;
    std::vector<std::string> paths;  // of each value
  };

  void Add(const OptionField& field, Target value) {
    if (*field.flag == '\0') return;
    auto [it, added] = flags_.try_emplace(field.flag, Targets{field, {}, {}});
    if (added) order_.push_back(field.flag);
    if (it->second.values.size() > 0 && it->second.values.front().index() != value.index()) {
      throw std::logic_error(std::string("matcher flag ") + field.flag + " has fields of different types");
    }
    it->second.values.push_back(value);
    it->second.paths.push_back(model_ + "." + field.key);
  }

  template <typename T>
  static CLI::Option* BindTargets(CLI::App* command, const std::string& flag, const Targets& targets, T* first) {
    const OptionField& field = targets.field;
    if (flag.front() == '!') {  // "!--no-x": a bool flag that sets false
      if constexpr (std::is_same_v<T, bool>) {
        if (targets.values.size() == 1) return command->add_flag(flag, *first, field.help);
      }
      throw std::logic_error("matcher flag " + flag + ": a negated flag needs exactly one bool field");
    }
    CLI::Option* option = nullptr;
    if (targets.values.size() == 1) {
      option = command->add_option(flag, *first, field.help);
      if (field.show_default) option->capture_default_str();
      return option;
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
    return option;
  }

  std::string model_;  // whose fields are visited
  std::map<std::string, Targets> flags_;
  std::vector<std::string> order_;  // as the models list them
};

}  // namespace

void AddMatcherOptions(CLI::App* command, MatcherOptions& options, OptionFlags& option_flags) {
  std::string models;
  for (const auto& model : MatcherModels()) models += "\n  " + model.name + ": " + model.summary;
  command->add_option("--matcher", options.type, "Feature matcher: " + MatcherModelNames() + models)
      ->capture_default_str();
  // Every model's flags, as its options list them (features/option_fields.h).
  FlagBinder binder;
  for (const auto& model : MatcherModels()) binder.VisitModel(model.name, options.model(model.name));
  binder.Bind(command, option_flags);
}

VerifierOptions VerifierFlags::Resolve() const {
  VerifierOptions resolved = options;
  CheckField("verifier", resolved);
  return resolved;
}

void AddVerifierOptions(CLI::App* command, VerifierFlags& flags, OptionFlags& option_flags,
                        bool with_early_stop) {
  option_flags.AddEnumOption(command, "--verifier", flags.options.method, ParseVerifierMethod, VerifierMethodName,
                             "verifier.method", "Fundamental matrix estimator: " + ListEnumNames(kVerifierMethodNames));
  option_flags
      .AddOption(command, "--threshold", flags.options.threshold, "verifier.threshold",
                 "Verifier inlier threshold in pixels")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--confidence", flags.options.confidence, "verifier.confidence", "Verifier confidence")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--max-iters", flags.options.max_iterations, "verifier.max_iterations",
                 "Verifier maximum iterations")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--seed", flags.options.seed, "verifier.seed", "Verifier random seed (same seed, same map)")
      ->capture_default_str();
  if (!with_early_stop) return;
  option_flags
      .AddOption(command, "--max-samples-to-reject", flags.options.max_samples_to_reject,
                 "verifier.max_samples_to_reject",
                 "Samples after which S < tau is settled when decisions stop early (--max-iters or more: the "
                 "confidence criterion alone; ignored with --exhaustive)")
      ->capture_default_str();
}

FrameSourceOptions SourceFlags::Resolve() const {
  FrameSourceOptions resolved = options;
  resolved.Check();
  return resolved;
}

void AddHeadingOptions(CLI::App* command, HeadingOptions& options, OptionFlags& option_flags) {
  option_flags
      .AddOption(command, "--heading-window", options.window_px, "heading.window_px",
                 "Heading: width of the window of horizontal displacements that votes (px)")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--heading-window-dy", options.window_dy_px, "heading.window_dy_px",
                 "Heading: height of the window in vertical displacement (px; 0 = by x alone)")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--heading-min-votes", options.min_votes, "heading.min_votes",
                 "Heading: the fewest agreeing matches for an estimate")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--heading-min-verified", options.min_verified, "heading.min_verified",
                 "Heading: with at least this many F-verified matches, their median displacement (0 = always the "
                 "mode of all matches)")
      ->capture_default_str();
}

void AddSourceOptions(CLI::App* command, SourceFlags& flags, OptionFlags& option_flags) {
  option_flags.AddEnumOption(command, "--format", flags.options.format, ParseSourceFormat, SourceFormatName, "format",
                             "Input layout: " + ListEnumNames(kSourceFormatNames));
  option_flags.AddOption(command, "--first", flags.options.first, "first", "First frame (0-based)")
      ->capture_default_str();
  option_flags.AddOption(command, "--last", flags.options.last, "last", "Last frame, inclusive (-1 = end)")
      ->capture_default_str();
  option_flags.AddOption(command, "--stride", flags.options.stride, "stride", "Use every N-th frame")
      ->capture_default_str();
  option_flags.AddOption(command, "--resize", flags.options.resize, "resize",
                         "Resize frames: WxH, or the longest side (e.g. 640)");
  option_flags.AddFlag(command, "--strict", flags.options.strict, "strict",
                       "Frames of a different size are an error, not a warning");
  option_flags.AddOption(command, "--camera", flags.options.camera, "camera",
                         "Intrinsics: fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]] (pixels, native frame size) or a calibration "
                         "file (OpenCV YAML/JSON, EuRoC sensor.yaml, KITTI calib.txt, intrinsics.txt); 'none' ignores "
                         "the input's own. Default: the input's own, if any");
  option_flags.AddOption(command, "--topic", flags.options.topic, "topic",
                         "Recordings (ROS bag, rosbag2, MCAP): the image topic (Image or CompressedImage). Default: "
                         "the only one; `vmap info RECORDING` lists them");
  option_flags.AddOption(command, "--camera-topic", flags.options.camera_topic, "camera_topic",
                         "Recordings: the CameraInfo topic. Default: camera_info beside the image topic");
  option_flags
      .AddOption(command, "--stream-timeout", flags.options.stream_timeout_seconds, "stream_timeout_seconds",
                 "Live inputs: seconds without a frame after which the stream has ended (and the longest opening "
                 "it may take)")
      ->capture_default_str();
}

}  // namespace vmap::cli
