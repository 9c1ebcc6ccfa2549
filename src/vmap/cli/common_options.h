#pragma once
// Command-line options shared by several subcommands, bound to the options structs of each stage.

#include <string>

#include <CLI/CLI.hpp>

#include "vmap/features/matcher_registry.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/sources/frame_source.h"

namespace vmap::cli {

// --matcher and the flags of every registered matcher model (features/matcher_registry.h).
void AddMatcherOptions(CLI::App* command, MatcherOptions& options);

// --verifier, --threshold, --confidence, --max-iters, --seed.
struct VerifierFlags {
  std::string method = "magsac";
  VerifierOptions options;
  VerifierOptions Resolve() const;  // parses method names
};
void AddVerifierOptions(CLI::App* command, VerifierFlags& flags);

// --format, --first, --last, --stride, --resize, --strict.
struct SourceFlags {
  std::string format = "auto";
  FrameSourceOptions options;
  FrameSourceOptions Resolve() const;
};
void AddSourceOptions(CLI::App* command, SourceFlags& flags);

}  // namespace vmap::cli
