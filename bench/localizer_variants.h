#pragma once
// The localizer settings a localization bench compares side by side (localize_accuracy, localize_repeat):
// "--acceptance counts,chance" (each rule with the other options at their defaults) or
// "--variants RULE/RECHECK/SHARE[/RIVAL[/RIVAL_NFA]],..." (rule, LocalizerOptions::recheck_link_share,
// min_link_share, min_rival_ratio and rival_max_log10_nfa; the defaults when not given).

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "vmap/localization/localizer.h"

namespace vmap::bench {

struct LocalizerVariant {
  AcceptanceRule rule = LocalizerOptions().acceptance;
  double recheck_link_share = LocalizerOptions().recheck_link_share;
  double min_link_share = LocalizerOptions().min_link_share;
  double min_rival_ratio = LocalizerOptions().min_rival_ratio;
  double rival_max_log10_nfa = LocalizerOptions().rival_max_log10_nfa;

  void ApplyTo(LocalizerOptions& options) const {
    options.acceptance = rule;
    options.recheck_link_share = recheck_link_share;
    options.min_link_share = min_link_share;
    options.min_rival_ratio = min_rival_ratio;
    options.rival_max_log10_nfa = rival_max_log10_nfa;
  }
  std::string Name() const {
    return fmt::format(
        "acceptance {}, recheck_link_share {:g}, min_link_share {:g}, min_rival_ratio {:g}, rival_max_log10_nfa {:g}",
        AcceptanceRuleName(rule), recheck_link_share, min_link_share, min_rival_ratio, rival_max_log10_nfa);
  }
};

inline std::vector<std::string> SplitList(const std::string& list, char separator) {
  std::vector<std::string> items;
  for (size_t start = 0; start <= list.size();) {
    const size_t end = std::min(list.find(separator, start), list.size());
    items.push_back(list.substr(start, end - start));
    start = end + 1;
  }
  return items;
}

// "counts,chance": the rules with the defaults of the other fields (min_link_share 0 with counts, which ignores it).
inline std::vector<LocalizerVariant> ParseAcceptanceVariants(const std::string& list) {
  std::vector<LocalizerVariant> variants;
  for (const std::string& name : SplitList(list, ',')) {
    LocalizerVariant v;
    v.rule = ParseAcceptanceRule(name);
    if (v.rule != AcceptanceRule::kChance) v.min_link_share = 0.0;
    variants.push_back(v);
  }
  return variants;
}

// "counts/0/0,chance/0.5/0.25,chance/0.5/0.4/0".
inline std::vector<LocalizerVariant> ParseLocalizerVariants(const std::string& list) {
  std::vector<LocalizerVariant> variants;
  for (const std::string& item : SplitList(list, ',')) {
    const std::vector<std::string> fields = SplitList(item, '/');
    if (fields.size() < 3 || fields.size() > 5) {
      throw std::runtime_error("--variants: " + item + " is not RULE/RECHECK/SHARE[/RIVAL[/RIVAL_NFA]]");
    }
    LocalizerVariant v{ParseAcceptanceRule(fields[0]), std::stod(fields[1]), std::stod(fields[2])};
    if (fields.size() >= 4) v.min_rival_ratio = std::stod(fields[3]);
    if (fields.size() == 5) v.rival_max_log10_nfa = std::stod(fields[4]);
    variants.push_back(v);
  }
  return variants;
}

// The variants of the bench's --acceptance and --variants lists (--variants when both are given); the localizer's
// defaults alone when neither is.
inline std::vector<LocalizerVariant> VariantsToCompare(const std::string& acceptance, const std::string& variant_list) {
  std::vector<LocalizerVariant> variants;
  if (!acceptance.empty()) variants = ParseAcceptanceVariants(acceptance);
  if (!variant_list.empty()) variants = ParseLocalizerVariants(variant_list);
  if (variants.empty()) variants.push_back({});
  return variants;
}

}  // namespace vmap::bench
