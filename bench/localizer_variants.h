#pragma once
// The localizer settings a localization bench compares side by side (localize_accuracy, localize_repeat):
// "--acceptance counts,chance" (each rule with the other options at their defaults) or
// "--variants RULE/RECHECK/SHARE,..." (rule, LocalizerOptions::recheck_link_share, min_link_share).

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

  void ApplyTo(LocalizerOptions& options) const {
    options.acceptance = rule;
    options.recheck_link_share = recheck_link_share;
    options.min_link_share = min_link_share;
  }
  std::string Name() const {
    return fmt::format("acceptance {}, recheck_link_share {:g}, min_link_share {:g}", AcceptanceRuleName(rule),
                       recheck_link_share, min_link_share);
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

// "counts/0/0,chance/0.5/0.25".
inline std::vector<LocalizerVariant> ParseLocalizerVariants(const std::string& list) {
  std::vector<LocalizerVariant> variants;
  for (const std::string& item : SplitList(list, ',')) {
    const std::vector<std::string> fields = SplitList(item, '/');
    if (fields.size() != 3) throw std::runtime_error("--variants: " + item + " is not RULE/RECHECK/SHARE");
    variants.push_back({ParseAcceptanceRule(fields[0]), std::stod(fields[1]), std::stod(fields[2])});
  }
  return variants;
}

}  // namespace vmap::bench
