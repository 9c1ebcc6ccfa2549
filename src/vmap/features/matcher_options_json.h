#pragma once
// The matcher a map was built with, rebuilt from what map.json records (`options.matcher`, the text of
// Matcher::DescribeOptionsJson). The model named by its `type` reads its own options (ModelOptions::FromJson).

#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher_registry.h"

namespace vmap {

// What a run that follows a map sets of the map's matcher: the run's business, not the map's.
struct MatcherRunSettings {
  // Where a deep matcher computes: "cpu", "cuda"; "" = where the map's did (a map taught on a GPU is followed on a
  // robot without one).
  std::string device;
  // The weights file of the map's model to read: "" = the file the map records, where it is here, or else the one
  // the weights directories hold (a map built on another machine, whose weights lie elsewhere on the robot).
  std::string weights;

  // "device" (--device) and "weights" (--weights), neither recorded: a run's, as `vmap localize` takes them.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming "device" when it is neither cpu nor cuda
};

// `matcher_json` is the JSON object of map.json's `options.matcher`. Fields the record lacks keep their
// defaults; a weights file recorded where the map was built that is not here is dropped (the weights
// directories are searched instead). Throws InputError naming `map_file` when the type is missing or unknown
// to this vmap, or a field is of the wrong type, and when `run` sets what the map's model does not have (a device
// other than the CPU, or weights, for ORB). Weights of another model are refused when the matcher is created.
MatcherOptions MatcherOptionsFromJson(const std::string& matcher_json, const std::string& map_file,
                                      const MatcherRunSettings& run = {});

}  // namespace vmap
