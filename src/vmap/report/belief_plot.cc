#include "vmap/report/belief_plot.h"

#include <algorithm>

#include <fmt/format.h>

#include "vmap/report/svg_plot.h"

namespace vmap::report {

std::string BeliefPlot(const LocalizationRun& run, int num_keys) {
  const bool recorded =
      std::any_of(run.frames.begin(), run.frames.end(), [](const LocalizationResult& r) { return !r.belief.empty(); });
  if (!recorded) return {};
  SvgPlot plot("belief-plot", "frame index", "key image");
  plot.SetIntegerX(true);
  plot.SetIntegerY(true);
  plot.SetYRange(0.0, std::max(1, num_keys - 1));
  PlotSeries mass, key;
  mass.kind = key.kind = PlotSeries::Kind::kMarkers;
  mass.name = "the belief (darker: more of it)";
  mass.color = kBlue;
  mass.css_class = "belief";
  mass.marker_radius = 2.5;
  key.name = "the frame's key image";
  key.color = kOrange;
  key.css_class = "belief-key";
  key.marker_radius = 1.5;
  key.segments.emplace_back();
  for (const LocalizationResult& r : run.frames) {
    for (const auto& [k, m] : r.belief) {
      // One segment per marker: each carries its own opacity.
      mass.segments.push_back({cv::Point2d(r.frame_index, k)});
      mass.segment_attributes.push_back(
          fmt::format("fill-opacity=\"{:.3f}\" data-mass=\"{:.3f}\"", std::clamp(0.1 + 0.9 * m, 0.0, 1.0), m));
      mass.point_titles.push_back(
          fmt::format("frame {}: {:.0f} % of the belief at key image {}", r.frame_index, 100.0 * m, k));
    }
    if (r.key >= 0) key.segments[0].emplace_back(r.frame_index, r.key);
  }
  plot.Add(std::move(mass));
  plot.Add(std::move(key));
  return plot.Render();
}

}  // namespace vmap::report
