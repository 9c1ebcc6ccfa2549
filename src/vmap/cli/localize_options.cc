#include "vmap/cli/localize_options.h"

#include <limits>

#include <fmt/format.h>

#include "vmap/cli/common_options.h"
#include "vmap/core/error.h"

namespace vmap::cli {

void AddLocalizerOptions(CLI::App* command, LocalizerFlags& flags, OptionFlags& option_flags) {
  LocalizerOptions& o = flags.localizer;
  option_flags.AddEnumOption(command, "--acceptance", o.acceptance, ParseAcceptanceRule, AcceptanceRuleName,
                             "acceptance",
                             "When a frame is seen at a key image: chance (its verified matches are unlikely by "
                             "chance, --max-log10-nfa) or counts (--min-verified and --min-similarity)");
  option_flags
      .AddOption(command, "--max-log10-nfa", o.max_log10_nfa, "max_log10_nfa",
                 "--acceptance chance: accept when log10 of the number of false alarms is at most this")
      ->capture_default_str();
  flags.counts_flags.push_back(
      option_flags
          .AddOption(command, "--min-verified", o.min_verified, "min_verified",
                     "--acceptance counts: verified matches a frame needs to be localized at a key image")
          ->capture_default_str());
  flags.counts_flags.push_back(option_flags
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
      .AddOption(command, "--experience-candidates", o.experience_candidates, "experience_candidates",
                 "Maps with experiences: views of a key image verified besides it, those with the most tentative "
                 "matches (0 = the teach key images only)")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--lookahead", o.lookahead, "lookahead",
                 "Key images beyond the next compared while tracking (1 or 2)")
      ->capture_default_str();
  option_flags.AddFlag(command, "!--no-step-back", o.step_back, "step_back",
                       "Never move the estimate back to the previous key image");
  option_flags.AddEnumOption(command, "--ranking", o.ranking.method, ParseRankingMethod, RankingMethodName,
                             "ranking.method", "Relocalization ranking: " + ListEnumNames(kRankingMethodNames));
  AddHeadingOptions(command, o.heading, option_flags);
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
      throw InputError(fmt::format("{} belongs to the earlier acceptance rule; add --acceptance counts to use it, "
                                   "or leave it out (--acceptance chance decides by --max-log10-nfa)",
                                   flag->get_name()));
    }
  }
}

}  // namespace vmap::cli
