#pragma once
// Command-line options shared by several subcommands, bound to the options structs of each stage.

#include <string>

#include <CLI/CLI.hpp>

#include "vmap/cli/option_flags.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/heading.h"
#include "vmap/sources/frame_source.h"

namespace vmap::cli {

// Each Add*Options records its flags in `option_flags` by the paths the checks of the options name.

// --matcher and the flags of every registered matcher model (features/matcher_registry.h); fields as
// MatcherOptions::Check() names them ("orb.num_features").
void AddMatcherOptions(CLI::App* command, MatcherOptions& options, OptionFlags& option_flags);

// --verifier, --threshold, --confidence, --max-iters, --seed and, for the commands whose decisions stop early
// (build, sweep), --max-samples-to-reject; fields as "verifier.<field>" (MapBuilderOptions, LocalizerOptions).
struct VerifierFlags {
  VerifierOptions options;
  VerifierOptions Resolve() const;  // checks the options as the field "verifier"
};
void AddVerifierOptions(CLI::App* command, VerifierFlags& flags, OptionFlags& option_flags,
                        bool with_early_stop = true);

// --heading-window, --heading-window-dy, --heading-min-votes, --heading-min-verified; fields as "heading.<field>"
// (MatchFlags, LocalizerOptions).
void AddHeadingOptions(CLI::App* command, HeadingOptions& options, OptionFlags& option_flags);

// --format, --first, --last, --stride, --resize, --strict, --camera, --topic, --camera-topic, --stream-timeout;
// fields as FrameSourceOptions names them.
struct SourceFlags {
  FrameSourceOptions options;
  FrameSourceOptions Resolve() const;  // checks the options
};
void AddSourceOptions(CLI::App* command, SourceFlags& flags, OptionFlags& option_flags);

}  // namespace vmap::cli
