#pragma once
// The localizer's options of `vmap localize` (and of the Python module's vmap.Localizer / vmap.localize, which
// take them by the same names).

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "vmap/cli/option_flags.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/localizer.h"
#include "vmap/sources/frame_source.h"

namespace vmap::cli {

struct LocalizerFlags {
  LocalizerOptions localizer;
  int from = -1;      // --from: the route's first key image; -1 = the first
  int to = -1;        // --to: its last; -1 = the last
  int threads = 0;    // LocalizeSequenceOptions::extraction_threads
  bool cache = true;  // the key-image cache in the map directory
  // --min-verified and --min-similarity: they belong to --acceptance counts alone, and are refused with chance.
  std::vector<const CLI::Option*> counts_flags;
  // --min-link-share: it belongs to --acceptance chance alone, and is refused with counts.
  std::vector<const CLI::Option*> chance_flags;
};

// --acceptance, --max-log10-nfa, --min-verified, --min-similarity, --min-link-share, --recheck-link-share, --max-lost,
// --candidates, --lookahead, --no-step-back, --ranking, the heading's options, --from, --to,
// --threads, --no-cache; fields as LocalizerOptions names them.
void AddLocalizerOptions(CLI::App* command, LocalizerFlags& flags, OptionFlags& option_flags);

// Refuses --min-verified or --min-similarity given with any acceptance rule but counts, which alone reads them,
// and --min-link-share with any but chance.
void CheckLocalizerFlags(const LocalizerFlags& flags);

// The route --from and --to plan on `map` (`route` when neither is given).
std::vector<int> RouteOf(const VisualMap& map, const LocalizerFlags& flags, std::vector<int> route);

// A query sequence ready to be localized against a map, as `vmap localize` and the Python module's
// vmap.localize set it up.
struct LocalizationSetup {
  FrameSourceOptions source_options;  // resized to the map's frame size unless --resize was given
  LocalizeSequenceOptions run_options;
  std::unique_ptr<FrameSource> source;
  std::unique_ptr<LocalizationMap> opened;  // the map, its matcher and key images (the Localizer refers to it)
  LocalizerOptions options;                 // following the map (FollowMap), along the route --from/--to plan
};
// Everything that can fail fast does before the key images are loaded (which may take seconds): the options
// are checked, then `checks` runs (the command's own: its outputs, its query), then the map's header is read and
// the query opened; then the map is opened for localization.
LocalizationSetup SetUpLocalization(const LocalizerFlags& flags, FrameSourceOptions source_options,
                                    const std::filesystem::path& map, const std::string& query,
                                    const std::function<void()>& checks = {});

}  // namespace vmap::cli
