#pragma once
// Plain-text and tabular views of maps and sweeps: what `vmap build`, `vmap info` and `vmap sweep` print.

#include <string>

#include "vmap/mapping/map_builder.h"
#include "vmap/mapping/visual_map.h"

namespace vmap {

// The build summary: n, m (% of frames), min/max/mean verified matches, Q, time and frames/s.
std::string FormatMapSummary(const VisualMap& map, QualityMean mean);

// The paper's table, one row per tau, the best tau (highest Q) marked.
std::string SweepToMarkdown(const SweepResult& sweep);
std::string SweepToCsv(const SweepResult& sweep);
std::string SweepToJson(const SweepResult& sweep);

}  // namespace vmap
