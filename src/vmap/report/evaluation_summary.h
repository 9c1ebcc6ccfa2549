#pragma once
// What `vmap eval` prints: one row per link and the summary.

#include <string>

#include "vmap/evaluation/map_evaluation.h"

namespace vmap {

// The per-link table (Markdown-style, aligned) and the summary lines below it.
std::string FormatEvaluationTable(const MapEvaluation& evaluation);
std::string FormatEvaluationSummary(const MapEvaluation& evaluation);

}  // namespace vmap
