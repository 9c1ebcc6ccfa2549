#pragma once
// The add-experience pipeline: a repeat run of the route added to a map as another experience (`vmap build
// REPEAT --add-experience-to MAP`): each key image gains the repeat frame that localized at it best
// (localization/add_experience.h). The map's teach run stays byte-identical; the add is atomic.

#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/localization/add_experience.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// The --help section of --add-experience-to and the repeat run's acceptance (`vmap build` binds those by hand).
inline constexpr char kAddExperienceSection[] = "Adding an experience to a map (docs/experiences.md)";

struct AddExperiencePipelineOptions {
  std::string input;  // the repeat run
  std::string map;    // the map it is added to
  // The matcher the caller expects; "" = the map's. Experiences are matched as the map's key images are: any
  // other is refused.
  std::string matcher;
  FrameSourceOptions source;
  AddExperienceOptions experience;  // how the run is localized against the map
  // Where the map's matcher computes and the weights file it reads, as `vmap localize` takes them (--device,
  // --weights): "" = the map's.
  MatcherRunSettings matcher_run;

  // The fields above, each once ("input", "map", "matcher", the input's, "experience.localizer.min_verified",
  // "experience.run.extraction_threads", "device", "weights").
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Stages, in order:
//   1. check the options;
//   2. read the map's header: its matcher must be the one expected;
//   3. open the repeat run;
//   4. localize it against the map and add its best frames as the new experience (AddExperience).
// Throws InputError (OptionError for an option) and leaves the map as it was on any failure.
AddExperienceSummary RunAddExperiencePipeline(const AddExperiencePipelineOptions& options);

}  // namespace vmap
