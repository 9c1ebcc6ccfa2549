#include "vmap/pipelines/add_experience_pipeline.h"

#include <filesystem>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap {

void AddExperiencePipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"input", "input", "The repeat run: a video, image folder, dataset or recording"}
                    .Positional()
                    .NotRecorded(),
                input);
  visitor.Section(kAddExperienceSection);
  visitor.Visit(OptionField{"map", "--add-experience-to",
                            "Add the input, a repeat run of the route, to this map as another experience: each key "
                            "image gains the frame that localized at it best (docs/experiences.md)"}
                    .HideDefault()
                    .NotRecorded(),
                map);
  visitor.Visit(OptionField{"matcher", "--matcher", "The map's matcher (default: the map's; no other is taken)"}
                    .HideDefault()
                    .NotRecorded(),
                matcher);
  visitor.VisitNested("", matcher_run);
  visitor.VisitNested("", source);
  // Its own level, so that a command that takes a few of its options can leave the rest out.
  visitor.VisitNested("experience", experience, Nesting{/*json_inline=*/true, {}});
}

void AddExperiencePipelineOptions::Check() const {
  source.Check();
  matcher_run.Check();
  CheckField("experience", experience);
}

AddExperienceSummary RunAddExperiencePipeline(const AddExperiencePipelineOptions& options) {
  // 1. The options.
  options.Check();

  // 2. The map's matcher, which its experiences are matched with.
  const RecordedMap header = ReadRecordedMap(options.map);
  const std::string& map_matcher = header.options.matcher_type;
  if (!options.matcher.empty() && options.matcher != map_matcher) {
    throw OptionError("matcher",
                      fmt::format("{}: the map '{}' was built with matcher {}, and its experiences are matched as "
                                  "its key images are; leave it out",
                                  options.matcher, options.map, map_matcher),
                      {"matcher"});
  }

  // 3. The repeat run.
  const std::unique_ptr<FrameSource> source = OpenFrameSource(options.input, options.source);

  // 4. The experience.
  AddExperienceOptions experience = options.experience;
  experience.run.show_progress = experience.run.show_progress && spdlog::should_log(spdlog::level::info);
  return AddExperience(options.map, *source, options.input, experience, options.matcher_run);
}

}  // namespace vmap
