#include "vmap/cli/common_options.h"

#include "vmap/cli/option_binder.h"

namespace vmap::cli {

void AddMatcherOptions(CLI::App* command, MatcherOptions& options, OptionFlags& option_flags) {
  std::string models;
  for (const auto& model : MatcherModels()) models += "\n  " + model.name + ": " + model.summary;
  command->add_option("--matcher", options.type, "Feature matcher: " + MatcherModelNames() + models)
      ->capture_default_str();
  // Every model's flags, as its options list them (core/option_fields.h); a flag several models share
  // (--weights, --device) sets the field of each, whichever --matcher is chosen. Each field is recorded as
  // "<model>.<key>", the path MatcherOptions::Check() names.
  OptionBinder binder;
  for (const auto& model : MatcherModels()) binder.Add(model.name.c_str(), options.model(model.name));
  binder.Bind(command, option_flags);
}

VerifierOptions VerifierFlags::Resolve() const {
  VerifierOptions resolved = options;
  CheckField("verifier", resolved);
  return resolved;
}

void AddVerifierOptions(CLI::App* command, VerifierFlags& flags, OptionFlags& option_flags, bool with_early_stop) {
  Nesting nesting;
  if (!with_early_stop) nesting.skip = {"max_samples_to_reject"};
  AddOptionFlags(command, flags.options, option_flags, "verifier", nesting);
}

FrameSourceOptions SourceFlags::Resolve() const {
  FrameSourceOptions resolved = options;
  resolved.Check();
  return resolved;
}

void AddHeadingOptions(CLI::App* command, HeadingOptions& options, OptionFlags& option_flags) {
  AddOptionFlags(command, options, option_flags, "heading");
}

void AddSourceOptions(CLI::App* command, SourceFlags& flags, OptionFlags& option_flags) {
  AddOptionFlags(command, flags.options, option_flags);
}

}  // namespace vmap::cli
