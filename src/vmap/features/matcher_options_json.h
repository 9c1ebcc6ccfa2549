#pragma once
// The matcher a map was built with, rebuilt from what map.json records (`options.matcher`, the text of
// Matcher::DescribeOptionsJson). The model named by its `type` reads its own options (ModelOptions::FromJson).

#include <string>

#include "vmap/features/matcher_registry.h"

namespace vmap {

// `matcher_json` is the JSON object of map.json's `options.matcher`. Fields the record lacks keep their
// defaults; a weights file recorded where the map was built that is not here is dropped (the weights
// directories are searched instead). Throws InputError naming `map_file` when the type is missing or unknown
// to this vmap, or a field is of the wrong type. `device` ("cpu", "cuda"; "" = the recorded one) is where this run
// computes: a run setting, not the map's (a map taught on a GPU is followed on a robot without one).
MatcherOptions MatcherOptionsFromJson(const std::string& matcher_json, const std::string& map_file,
                                      const std::string& device = "");

}  // namespace vmap
