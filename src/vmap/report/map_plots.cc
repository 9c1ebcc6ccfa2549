#include "vmap/report/map_plots.h"

#include <algorithm>
#include <map>
#include <vector>

#include "vmap/report/html_report.h"
#include "vmap/report/html_util.h"
#include "vmap/report/svg_plot.h"

namespace vmap::report {

std::string SimilarityPlot(const VisualMap& map, double tau) {
  SvgPlot plot("similarity-plot", "frame index", "similarity S(key, frame)");
  plot.SetIntegerX(true);
  double y_high = 1.0;
  std::map<int, std::vector<const Evaluation*>> by_key;
  std::vector<int> key_order;
  for (const Evaluation& e : map.evaluations) {
    if (!by_key.count(e.key_frame)) key_order.push_back(e.key_frame);
    by_key[e.key_frame].push_back(&e);
    y_high = std::max(y_high, e.similarity);
  }
  for (const Link& l : map.links) y_high = std::max(y_high, l.similarity);
  plot.SetYRange(0.0, y_high);
  const int last_frame = std::max(map.num_frames - 1, 1);
  plot.SetXRange(0.0, last_frame);

  PlotSeries lines;
  lines.name = "S(key, frame)";
  lines.color = kBlue;
  lines.css_class = "evaluations";
  PlotSeries failed;
  failed.kind = PlotSeries::Kind::kCrosses;
  failed.name = "matching failed";
  failed.color = kRed;
  failed.css_class = "failed";
  failed.segments.emplace_back();
  for (int key_frame : key_order) {
    std::vector<const Evaluation*>& evaluations = by_key[key_frame];
    std::stable_sort(evaluations.begin(), evaluations.end(),
                     [](const Evaluation* a, const Evaluation* b) { return a->frame < b->frame; });
    std::vector<cv::Point2d> points;
    for (const Evaluation* e : evaluations) {
      points.emplace_back(e->frame, e->similarity);
      if (!e->matched) failed.segments[0].emplace_back(e->frame, e->similarity);
    }
    lines.segments.push_back(std::move(points));
    lines.segment_attributes.push_back("data-key-frame=\"" + std::to_string(key_frame) + "\"");
  }

  PlotSeries keys;
  keys.kind = PlotSeries::Kind::kVerticalRules;
  keys.name = "key image";
  keys.color = kGrey;
  keys.css_class = "key-images";
  keys.segments.emplace_back();
  for (const KeyImage& k : map.key_images) keys.segments[0].emplace_back(k.frame_index, 0.0);

  PlotSeries links, below_tau;
  links.kind = below_tau.kind = PlotSeries::Kind::kMarkers;
  links.name = "link S (next key image)";
  links.color = kGreen;
  links.css_class = "links";
  below_tau.name = "link below \u03c4";
  below_tau.color = kRed;
  below_tau.css_class = "below-tau-links";
  below_tau.marker_radius = 5.0;
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    PlotSeries& target = l.below_tau ? below_tau : links;
    target.segments.push_back({cv::Point2d(map.key_images[l.to_key].frame_index, l.similarity)});
    target.segment_attributes.push_back("data-link=\"" + std::to_string(i) + "\"");
    target.point_titles.push_back(LinkTitle(map, static_cast<int>(i)) + ": S = " + FormatFixed(l.similarity, 3));
  }

  plot.Add(keys);
  if (!lines.segments.empty()) plot.Add(lines);
  if (!failed.segments[0].empty()) plot.Add(failed);
  PlotSeries rule;
  rule.kind = PlotSeries::Kind::kHorizontalRule;
  rule.name = "\u03c4 = " + FormatExact(tau);
  rule.color = kOrange;
  rule.css_class = "tau";
  rule.segments.push_back({cv::Point2d(0.0, tau)});
  rule.segment_attributes.push_back("data-tau=\"" + FormatExact(tau) + "\"");
  plot.Add(rule);
  if (!links.segments.empty()) plot.Add(links);
  if (!below_tau.segments.empty()) plot.Add(below_tau);
  return plot.Render();
}

std::string VerifiedPlot(const VisualMap& map) {
  SvgPlot plot("verified-plot", "frame index of the link's second key image", "verified matches");
  plot.SetSize(960, 260);
  plot.SetIntegerX(true);
  plot.SetIntegerY(true);
  plot.SetXRange(0.0, std::max(map.num_frames - 1, 1));
  PlotSeries line;
  line.name = "verified matches per link";
  line.color = kGreen;
  line.css_class = "verified";
  line.segments.emplace_back();
  PlotSeries tentative = line;
  tentative.name = "tentative matches";
  tentative.color = kGrey;
  tentative.css_class = "tentative";
  double high = 10.0;
  for (const Link& l : map.links) {
    const double x = map.key_images[l.to_key].frame_index;
    line.segments[0].emplace_back(x, l.num_verified);
    tentative.segments[0].emplace_back(x, l.num_tentative);
    high = std::max<double>(high, l.num_tentative);
  }
  plot.SetYRange(0.0, high);
  PlotSeries dots = line;
  dots.kind = PlotSeries::Kind::kMarkers;
  dots.name.clear();
  dots.marker_radius = 2.5;
  plot.Add(tentative);
  plot.Add(line);
  plot.Add(dots);
  return plot.Render();
}

}  // namespace vmap::report
