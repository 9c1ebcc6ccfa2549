#include "vmap/cli/other_matcher_flags.h"

#include <map>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "vmap/core/error.h"
#include "vmap/features/matcher_registry.h"

namespace vmap::cli {

void RefuseOtherMatchersFlags(const OptionFlags& flags, const std::string& matcher) {
  std::set<std::string> models;
  for (const MatcherModel& model : MatcherModels()) models.insert(model.name);
  std::map<std::string, std::set<std::string>> models_by_flag;  // of the matchers' fields given
  for (const std::string& path : flags.Given()) {
    const std::string model = path.substr(0, path.find('.'));
    if (model.size() < path.size() && models.count(model) > 0) models_by_flag[flags.FlagOf(path)].insert(model);
  }
  for (const auto& [flag, of] : models_by_flag) {
    if (flag.empty() || of.count(matcher) > 0) continue;
    throw InputError(fmt::format("{} is an option of {}, and the matcher is {}: drop it, or give --matcher {}", flag,
                                 fmt::join(of, ", "), matcher, *of.begin()));
  }
}

}  // namespace vmap::cli
