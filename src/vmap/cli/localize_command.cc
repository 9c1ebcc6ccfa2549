// vmap localize MAP QUERY: localizes every frame of a repeat run (or one image) against a map.

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/common_options.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localization_output.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/route.h"
#include "vmap/map/map_io.h"
#include "vmap/report/localization_report.h"

namespace vmap::cli {
namespace fs = std::filesystem;

namespace {

struct LocalizeFlags {
  std::string map;
  std::string query;
  std::string csv;
  std::string json;
  std::string report;
  SourceFlags source;
  LocalizerOptions localizer;
  int from = -1;
  int to = -1;
  int threads = 0;
  bool cache = true;
  OptionFlags option_flags;
  // The earlier acceptance rule's flags: given, they need --acceptance counts.
  std::vector<const CLI::Option*> counts_flags;
};

std::string Percent(long part, long whole) {
  return whole > 0 ? fmt::format("{:.1f}%", 100.0 * part / whole) : "-";
}

void RunLocalize(const LocalizeFlags& flags) {
  FrameSourceOptions source_options = flags.source.Resolve();
  source_options.allow_single_image = true;
  LocalizeSequenceOptions run_options;
  run_options.extraction_threads = flags.threads;
  run_options.show_progress = spdlog::should_log(spdlog::level::info);
  run_options.Check();

  // Everything that can fail fast does, before the key images are loaded (which may take seconds).
  LocalizerOptions options = flags.localizer;
  options.Check();
  for (const CLI::Option* flag : flags.counts_flags) {
    if (flag->count() > 0 && options.acceptance != AcceptanceRule::kCounts) {
      throw InputError(fmt::format("{} belongs to the earlier acceptance rule; add --acceptance counts to use it, "
                                   "or leave it out (--acceptance chance decides by --max-log10-nfa)",
                                   flag->get_name()));
    }
  }
  const VisualMap header = ReadMap(flags.map);
  if (flags.from >= 0 || flags.to >= 0) {
    const int last = static_cast<int>(header.key_images.size()) - 1;
    options.route = PlanRoute(header, flags.from >= 0 ? flags.from : 0, flags.to >= 0 ? flags.to : last).keys;
  }
  // Frames are compared with key images at the map's size unless told otherwise.
  const std::string map_size = fmt::format("{}x{}", header.input.frame_size.width, header.input.frame_size.height);
  if (source_options.resize.empty() && !header.input.frame_size.empty()) source_options.resize = map_size;
  const std::unique_ptr<FrameSource> source = OpenFrameSource(flags.query, source_options);

  KeyImageStoreOptions store_options;
  store_options.use_cache = flags.cache;
  store_options.thumbnail_width = options.ranking.thumbnail_width;
  LocalizationMap opened = OpenLocalizationMap(flags.map, store_options);
  const VisualMap& map = opened.map;
  // The map's verifier and definition of S.
  const LocalizerOptions from_map = MapLocalizerOptions(map);
  options.verifier = from_map.verifier;
  options.similarity = from_map.similarity;
  // The map's camera describes frames of the map's size: headings in degrees and poses need the query at it.
  if (from_map.camera && source_options.resize == map_size) {
    options.camera = from_map.camera;
  } else if (from_map.camera) {
    spdlog::warn("--resize {} differs from the map's frame size {}: headings in pixels only, no relative poses",
                 source_options.resize, map_size);
  }
  options.Check();
  Localizer localizer(map, opened.keys, *opened.matcher, options);

  LocalizationRun run;
  run.info.map_directory = flags.map;
  run.info.query = flags.query;
  run.info.query_format = source->info().format;
  run.info.source = source_options;
  run.info.matcher = opened.matcher->name();
  run.info.ranking = RankingMethodName(localizer.ranking_method());
  run.info.cache = KeyImageCacheStateName(opened.keys.cache);
  run.info.key_image_seconds = opened.keys.seconds;
  run.info.options_json = DescribeLocalizerOptions(options);
  std::string csv = LocalizationCsvHeader();
  run.summary = LocalizeSequence(*source, *opened.matcher, localizer, run_options,
                                 [&](const Frame&, const LocalizationResult& result) {
                                   if (!flags.csv.empty()) csv += LocalizationCsvRow(map, result);
                                   run.frames.push_back(result);
                                 });
  run.info.frame_size = source->info().frame_size;

  if (!flags.csv.empty()) WriteFileAtomically(flags.csv, csv);
  if (!flags.json.empty()) WriteFileAtomically(flags.json, LocalizationRunJson(map, run));
  if (!flags.report.empty()) WriteLocalizationReport(run, map, flags.map, flags.report);

  const LocalizationSummary& s = run.summary;
  std::cout << fmt::format("map             {} ({} key images, {})\n", flags.map, map.key_images.size(),
                           opened.matcher->name())
            << fmt::format("query           {} ({})\n", flags.query, SourceFormatName(run.info.query_format))
            << fmt::format("key images      {:.2f} s (cache: {}), ranking by {}\n", opened.keys.seconds,
                           run.info.cache, run.info.ranking)
            << fmt::format("frames          {}\n", s.frames)
            << fmt::format("tracking        {} ({})\n", s.tracking, Percent(s.tracking, s.frames))
            << fmt::format("relocalized     {} ({})\n", s.relocalized, Percent(s.relocalized, s.frames))
            << fmt::format("lost            {} ({})\n", s.lost, Percent(s.lost, s.frames))
            << fmt::format("time            {:.2f} s ({:.1f} frames/s)\n", s.seconds, s.frames_per_second);
  if (run.frames.size() == 1) {
    const LocalizationResult& r = run.frames.front();
    std::cout << fmt::format("status          {}\n", LocalizationStatusName(r.status))
              << fmt::format("key             {} -> next {}\n", r.key, r.next_key);
  }
  if (!flags.csv.empty()) std::cout << "csv             " << flags.csv << "\n";
  if (!flags.json.empty()) std::cout << "json            " << flags.json << "\n";
  if (!flags.report.empty()) std::cout << "report          " << (fs::path(flags.report) / "report.html").string() << "\n";
}

}  // namespace

void AddLocalizeCommand(CLI::App& app) {
  auto flags = std::make_shared<LocalizeFlags>();
  CLI::App* command = app.add_subcommand(
      "localize", "Localize a repeat run (video, image folder, dataset or one image) against a map, frame by frame");
  command->add_option("map", flags->map, "Map directory written by `vmap build`")->required();
  command->add_option("query", flags->query, "Video, image folder, TUM/EuRoC/KITTI sequence, or a single image")
      ->required();
  command->add_option("--csv", flags->csv, "Write one row per frame to this CSV file");
  command->add_option("--json", flags->json, "Write the run (summary and every frame) to this JSON file");
  command->add_option("--report", flags->report, "Write an HTML report of the run into this directory");
  OptionFlags& option_flags = flags->option_flags;
  AddSourceOptions(command, flags->source, option_flags);
  LocalizerOptions& o = flags->localizer;
  option_flags.AddEnumOption(command, "--acceptance", o.acceptance, ParseAcceptanceRule, AcceptanceRuleName,
                             "acceptance",
                             "When a frame is seen at a key image: chance (its verified matches are unlikely by "
                             "chance, --max-log10-nfa) or counts (--min-verified and --min-similarity)");
  option_flags
      .AddOption(command, "--max-log10-nfa", o.max_log10_nfa, "max_log10_nfa",
                 "--acceptance chance: accept when log10 of the number of false alarms is at most this")
      ->capture_default_str();
  flags->counts_flags.push_back(
      option_flags
          .AddOption(command, "--min-verified", o.min_verified, "min_verified",
                     "--acceptance counts: verified matches a frame needs to be localized at a key image")
          ->capture_default_str());
  flags->counts_flags.push_back(option_flags
                                    .AddOption(command, "--min-similarity", o.min_similarity, "min_similarity",
                                               "--acceptance counts: S a frame needs to be localized at a key image")
                                    ->capture_default_str());
  option_flags
      .AddOption(command, "--max-lost", o.max_lost_frames, "max_lost_frames",
                 "Lost frames in a row before the estimate is dropped")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--candidates", o.relocalization_candidates, "relocalization_candidates",
                 "Best-ranked key images verified when relocalizing")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--lookahead", o.lookahead, "lookahead",
                 "Key images beyond the next compared while tracking (1 or 2)")
      ->capture_default_str();
  option_flags.AddFlag(command, "!--no-step-back", o.step_back, "step_back",
                       "Never move the estimate back to the previous key image");
  option_flags.AddEnumOption(command, "--ranking", o.ranking.method, ParseRankingMethod, RankingMethodName,
                             "ranking.method", "Relocalization ranking: " + ListEnumNames(kRankingMethodNames));
  command->add_option("--from", flags->from, "Follow the route from this key image (default: the first)");
  command->add_option("--to", flags->to, "Follow the route to this key image (default: the last)");
  // LocalizeSequenceOptions::extraction_threads (the key-image store's keeps its default).
  option_flags
      .AddOption(command, "--threads", flags->threads, "extraction_threads",
                 "Feature-extraction threads (0 = one per core)")
      ->capture_default_str();
  command->add_flag("!--no-cache", flags->cache, "Do not read or write the key-image cache in the map directory");
  command->callback([flags] { flags->option_flags.Run([&] { RunLocalize(*flags); }); });
}

}  // namespace vmap::cli
