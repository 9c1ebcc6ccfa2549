#pragma once
// eval.json: a map's evaluation (evaluation/map_evaluation.h) written, and read back for the report.

#include <string>

#include "vmap/evaluation/map_evaluation.h"

namespace vmap {

inline constexpr const char* kEvaluationFileName = "eval.json";

// JSON document ("format": "vmap-eval") with the options, one object per link and the summary.
std::string EvaluationToJson(const MapEvaluation& evaluation);
// Reads eval.json back (for the report). Throws InputError naming the file when it is malformed.
MapEvaluation ReadEvaluation(const std::string& path);

}  // namespace vmap
