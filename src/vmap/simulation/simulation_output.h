#pragma once
// What a simulation writes: its JSON record (`vmap simulate --json`), the HTML report (`--report DIR`: the
// taught and repeated trajectories from above, the lateral error against the distance along the route, a row per
// trial) and a top view as a picture.

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "vmap/simulation/closed_loop.h"

namespace vmap {

// The run: options, route, teach run, summary, and each trial with its samples (columns of numbers).
nlohmann::json SimulationJson(const SimulationResult& result, const SimulationOptions& options);

// The corridor, the taught path with its key images and every trial's trajectory seen from above (successes
// green, failures red), `width` pixels wide.
cv::Mat DrawTopView(const SimulationResult& result, const SimulationOptions& options, int width = 900);

// report.html and top_view.png into `directory` (which must exist); the page opens offline.
void WriteSimulationReport(const SimulationResult& result, const SimulationOptions& options,
                           const std::filesystem::path& directory);

}  // namespace vmap
