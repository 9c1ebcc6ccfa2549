#include "vmap/pipelines/route_pipeline.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/option_ranges.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/output_policies.h"

namespace vmap {

namespace {

nlohmann::json RouteJson(const RoutePipelineOptions& options, const RoutePipelineResult& result) {
  const VisualMap& map = result.map;
  nlohmann::json steps = nlohmann::json::array();
  for (const RouteStep& s : result.route.steps) {
    const Link& l = map.links[s.link];
    steps.push_back({{"from", s.from_key},
                     {"to", s.to_key},
                     {"from_frame", map.key_images[s.from_key].frame_index},
                     {"to_frame", map.key_images[s.to_key].frame_index},
                     {"link", s.link},
                     {"backwards", s.backwards},
                     {"unverified", s.unverified},
                     {"similarity", l.similarity},
                     {"verified", l.num_verified},
                     {"translation_known", l.has_pose && l.translation_known},
                     {"translation_sigma_deg", l.translation_sigma_deg >= 0 ? nlohmann::json(l.translation_sigma_deg)
                                                                            : nlohmann::json(nullptr)}});
  }
  // The map's path percent-encoded where it is not UTF-8, as in map.json (file_name_encoding.h).
  return {{"format", "vmap-route"},
          {"schema_version", 1},
          {"vmap_version", VMAP_VERSION},
          {"map", EncodeFileName(options.map)},
          {"from", options.from},
          {"to", result.to},
          {"keys", result.route.keys},
          {"steps", steps},
          {"warnings", result.route.warnings}};
}

}  // namespace

void RoutePipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"map", "map", "Map directory written by `vmap build`"}.Positional(), map);
  visitor.Visit(OptionField{"from", "--from", "Start key image"}.AtLeast(0).NotRecorded(), from);
  visitor.Visit(OptionField{"to", "--to", "Goal key image (default: the last)"}
                    .AtLeast(0)
                    .Or(-1)
                    .Meaning("-1: the last")
                    .HideDefault()
                    .NotRecorded(),
                to);
  visitor.Visit(OptionField{"json", "--json", "Also write the route to this JSON file"}.HideDefault().NotRecorded(),
                json);
  visitor.VisitNested("", route);
}

void RoutePipelineOptions::Check() const {
  CheckFieldRanges(*this);  // --to -2 was taken for the last key image
  route.Check();
}

RoutePipelineResult RunRoutePipeline(const RoutePipelineOptions& options) {
  // 1. The options and the output.
  options.Check();
  CheckOutputs({{options.json, "json"}}, {MapInputs(options.map)});

  // 2. The map.
  RoutePipelineResult result;
  result.map = ReadMap(options.map);

  // 3. The route.
  CheckKeyImageOption(result.map, options.from, "from");
  CheckKeyImageOption(result.map, options.to, "to");
  result.to = options.to >= 0 ? options.to : static_cast<int>(result.map.key_images.size()) - 1;
  result.route = PlanRoute(result.map, options.from, result.to, options.route);
  for (const std::string& warning : result.route.warnings) spdlog::warn("{}", warning);

  // 4. Its record.
  if (!options.json.empty()) WriteFileAtomically(options.json, RouteJson(options, result).dump(1) + "\n");
  return result;
}

}  // namespace vmap
