#pragma once
// The matcher a map was built with, rebuilt from what map.json records (`options.matcher`, the text of
// Matcher::DescribeOptionsJson). The one place that reads it back, until options are typed.

#include <string>

#include "vmap/features/matcher_factory.h"

namespace vmap {

// `matcher_json` is the JSON object of map.json's `options.matcher`. Fields the record lacks keep their
// defaults. Throws InputError naming `map_file` when the type is missing or unknown to this vmap.
MatcherOptions MatcherOptionsFromJson(const std::string& matcher_json, const std::string& map_file);

}  // namespace vmap
