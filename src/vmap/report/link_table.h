#pragma once
// The report's table of links: what each link stores besides S and F (pose, parallax, homography test)
// and, when `vmap eval` has written eval.json into the map, how each link fares against ground truth.

#include <filesystem>
#include <optional>
#include <string>

#include "vmap/evaluation/map_evaluation.h"
#include "vmap/map/visual_map.h"

namespace vmap {

// The map's eval.json when there is one that belongs to this map (same links, same key frames); nullopt
// otherwise (with a warning when a stale or malformed one is ignored).
std::optional<MapEvaluation> ReadMatchingEvaluation(const std::filesystem::path& map_directory, const VisualMap& map);

// An HTML <section id="link-table"> with one row per link, and the evaluation's summary when given.
std::string LinkTableHtml(const VisualMap& map, const MapEvaluation* evaluation);

// A short text for a link's figure caption: "rotation error 0.21 deg, translation error 3.4 deg, usable".
std::string EvaluationCaption(const LinkEvaluation& evaluation);

}  // namespace vmap
