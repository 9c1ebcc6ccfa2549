#pragma once
// The localizer's options of `vmap localize` (and of the Python module's vmap.Localizer / vmap.localize, which
// take them by the same names).

#include <vector>

#include <CLI/CLI.hpp>

#include "vmap/cli/option_flags.h"
#include "vmap/localization/localizer.h"

namespace vmap::cli {

struct LocalizerFlags {
  LocalizerOptions localizer;
  int from = -1;     // --from: the route's first key image; -1 = the first
  int to = -1;       // --to: its last; -1 = the last
  int threads = 0;   // LocalizeSequenceOptions::extraction_threads
  bool cache = true;  // the key-image cache in the map directory
  // --min-verified and --min-similarity: they belong to --acceptance counts alone, and are refused with chance.
  std::vector<const CLI::Option*> counts_flags;
  // --min-link-share: it belongs to --acceptance chance alone, and is refused with counts.
  std::vector<const CLI::Option*> chance_flags;
};

// --acceptance, --max-log10-nfa, --min-verified, --min-similarity, --min-link-share, --recheck-link-share, --max-lost, --candidates, --lookahead, --no-step-back, --ranking, the heading's options, --from, --to,
// --threads, --no-cache; fields as LocalizerOptions names them.
void AddLocalizerOptions(CLI::App* command, LocalizerFlags& flags, OptionFlags& option_flags);

// Refuses --min-verified or --min-similarity given with any acceptance rule but counts, which alone reads them,
// and --min-link-share with any but chance.
void CheckLocalizerFlags(const LocalizerFlags& flags);

}  // namespace vmap::cli
