#pragma once
// The route pipeline: the key images to follow from one key image of a map to another (`vmap route MAP --from I
// --to J`), and its JSON record.

#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/localization/route.h"
#include "vmap/map/visual_map.h"

namespace vmap {

struct RoutePipelineOptions {
  std::string map;   // the map directory
  int from = 0;      // the start key image
  int to = -1;       // the goal key image; -1 = the last
  std::string json;  // the route as JSON; "" = none
  RouteOptions route;

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct RoutePipelineResult {
  VisualMap map;
  int to = -1;  // resolved
  Route route;
};

// Stages, in order:
//   1. check the options and the output (it may not overwrite the map);
//   2. read the map;
//   3. plan the route (PlanRoute);
//   4. write its JSON when asked.
RoutePipelineResult RunRoutePipeline(const RoutePipelineOptions& options);

}  // namespace vmap
