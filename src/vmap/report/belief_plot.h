#pragma once
// The localization report's plot of the belief over the route (localization/route_belief.h) over time: for each
// frame, the route positions holding part of the belief (each drawn at its key image, darker where the belief
// holds more), and the key image the frame was placed at.

#include <string>

#include "vmap/localization/localization_output.h"

namespace vmap::report {

// The <svg> element (id "belief-plot"): one marker per frame and key image of the frame's recorded belief
// (LocalizationResult::belief), its opacity the belief's mass there (class "belief", data-mass), and the frame's
// key image (class "belief-key"). `num_keys`: the map's key images (the y axis). A run without a recorded belief
// (written before it was recorded) gives an empty string.
std::string BeliefPlot(const LocalizationRun& run, int num_keys);

}  // namespace vmap::report
