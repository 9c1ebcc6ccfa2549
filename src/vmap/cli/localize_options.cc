#include "vmap/cli/localize_options.h"

#include <limits>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/cli/option_binder.h"
#include "vmap/core/error.h"
#include "vmap/localization/route.h"
#include "vmap/map/map_io.h"

namespace vmap::cli {

void AddLocalizerOptions(CLI::App* command, LocalizerFlags& flags, OptionFlags& option_flags) {
  // The verifier and the translation thresholds follow the map; they have no flags here.
  AddOptionFlags(command, flags.localizer, option_flags, "", Nesting{false, {"verifier", "translation"}});
  flags.counts_flags = {command->get_option("--min-verified"), command->get_option("--min-similarity")};
  flags.chance_flags = {command->get_option("--min-link-share")};
  // -1 stands for "not given" here only: a negative key image is refused as route refuses it.
  command->add_option("--from", flags.from, "Follow the route from this key image (default: the first)")
      ->check(CLI::Range(0, std::numeric_limits<int>::max()));
  command->add_option("--to", flags.to, "Follow the route to this key image (default: the last)")
      ->check(CLI::Range(0, std::numeric_limits<int>::max()));
  // LocalizeSequenceOptions::extraction_threads (the key-image store's keeps its default).
  option_flags
      .AddOption(command, "--threads", flags.threads, "extraction_threads",
                 "Feature-extraction threads (0 = one per core)")
      ->capture_default_str();
  command->add_flag("!--no-cache", flags.cache, "Do not read or write the key-image cache in the map directory");
}

void CheckLocalizerFlags(const LocalizerFlags& flags) {
  for (const CLI::Option* flag : flags.counts_flags) {
    if (flag->count() > 0 && flags.localizer.acceptance != AcceptanceRule::kCounts) {
      throw InputError(
          fmt::format("{} belongs to the earlier acceptance rule; add --acceptance counts to use it, "
                      "or leave it out (--acceptance chance decides by --max-log10-nfa)",
                      flag->get_name()));
    }
  }
  for (const CLI::Option* flag : flags.chance_flags) {
    if (flag->count() > 0 && flags.localizer.acceptance != AcceptanceRule::kChance) {
      throw InputError(fmt::format("{} belongs to --acceptance chance; add it to use {}, or leave {} out",
                                   flag->get_name(), flag->get_name(), flag->get_name()));
    }
  }
}

std::vector<int> RouteOf(const VisualMap& map, const LocalizerFlags& flags, std::vector<int> route) {
  if (flags.from < 0 && flags.to < 0) return route;
  const int last = static_cast<int>(map.key_images.size()) - 1;
  return PlanRoute(map, flags.from >= 0 ? flags.from : 0, flags.to >= 0 ? flags.to : last).keys;
}

LocalizationSetup SetUpLocalization(const LocalizerFlags& flags, FrameSourceOptions source_options,
                                    const std::filesystem::path& map, const std::string& query,
                                    const std::function<void()>& checks) {
  LocalizationSetup setup;
  source_options.allow_single_image = true;
  setup.run_options.extraction_threads = flags.threads;
  setup.run_options.show_progress = spdlog::should_log(spdlog::level::info);
  setup.run_options.Check();
  LocalizerOptions options = flags.localizer;
  options.Check();
  if (checks) checks();
  CheckLocalizerFlags(flags);
  const VisualMap header = ReadMap(map);
  options.route = RouteOf(header, flags, options.route);
  // Frames are compared with key images at the map's size unless told otherwise.
  source_options.resize = QueryResize(header, source_options.resize);
  setup.source = OpenFrameSource(query, source_options);

  KeyImageStoreOptions store_options;
  store_options.use_cache = flags.cache;
  store_options.thumbnail_width = options.ranking.thumbnail_width;
  setup.opened = std::make_unique<LocalizationMap>(OpenLocalizationMap(map, store_options));
  // The map's verifier, definition of S, translation thresholds and camera.
  setup.options = FollowMap(*setup.opened, options, source_options.resize);
  setup.options.Check();
  setup.source_options = std::move(source_options);
  return setup;
}

}  // namespace vmap::cli
