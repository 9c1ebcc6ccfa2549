#pragma once
// The plots of a map's report (report/html_report.cc), as inline SVG.

#include <string>

#include "vmap/map/visual_map.h"

namespace vmap::report {

// The S(key, frame) plot: one line per key image over the frames compared with it, tau, the key images
// and the similarity of each link at the frame that became the next key image.
std::string SimilarityPlot(const VisualMap& map, double tau);

// The verified and tentative matches of each link, at the frame of its second key image.
std::string VerifiedPlot(const VisualMap& map);

}  // namespace vmap::report
