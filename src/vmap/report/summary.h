#pragma once
// Plain-text and tabular views of maps and sweeps: what `vmap build`, `vmap info` and `vmap sweep` print.

#include <filesystem>
#include <string>

#include "vmap/map/visual_map.h"
#include "vmap/mapping/batch_build.h"

namespace vmap {

// The build summary: n, m (% of frames), min/max/mean verified matches, Q, time and frames/s.
std::string FormatMapSummary(const VisualMap& map, QualityMean mean);

// The paper's table, one row per tau, the best tau (highest Q) marked.
std::string SweepToMarkdown(const SweepResult& sweep);
std::string SweepToCsv(const SweepResult& sweep);
// sweep.json: "format": "vmap-sweep", "schema_version": 1; paths percent-encoded (file_name_encoding.h).
std::string SweepToJson(const SweepResult& sweep);

inline constexpr const char* kSweepJsonFileName = "sweep.json";

// The proof that `directory` holds a sweep vmap wrote, so that `vmap sweep -o` may replace it: "" when its
// sweep.json is vmap's ("format": "vmap-sweep" and an integer "schema_version"), otherwise why it is not.
std::string WhyNotAVmapSweep(const std::filesystem::path& directory);

}  // namespace vmap
