#include "vmap/report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "vmap/report/html_util.h"

namespace vmap::report {

AxisTicks NiceTicks(double low, double high, int target) {
  if (!std::isfinite(low) || !std::isfinite(high)) low = 0.0, high = 1.0;
  if (low > high) std::swap(low, high);
  if (high - low < 1e-12) {
    // A single value still needs an axis around it.
    const double pad = std::abs(low) > 1e-12 ? std::abs(low) * 0.1 : 1.0;
    low -= pad;
    high += pad;
  }
  target = std::max(target, 2);
  const double raw_step = (high - low) / (target - 1);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw_step)));
  const double fraction = raw_step / magnitude;
  double nice = 10.0;
  if (fraction <= 1.0)
    nice = 1.0;
  else if (fraction <= 2.0)
    nice = 2.0;
  else if (fraction <= 5.0)
    nice = 5.0;
  AxisTicks ticks;
  ticks.step = nice * magnitude;
  // The epsilon keeps a limit that is already a multiple of the step from gaining an extra tick.
  const double eps = ticks.step * 1e-9;
  ticks.low = std::floor((low + eps) / ticks.step) * ticks.step;
  ticks.high = std::ceil((high - eps) / ticks.step) * ticks.step;
  const int count = static_cast<int>(std::lround((ticks.high - ticks.low) / ticks.step));
  for (int i = 0; i <= count; ++i) ticks.values.push_back(ticks.low + i * ticks.step);
  ticks.decimals = std::max(0, -static_cast<int>(std::floor(std::log10(ticks.step) + 1e-9)));
  return ticks;
}

namespace {

struct Box {
  double left, right, top, bottom;
};

// Data ranges widen to the enclosing round ticks; a fixed range is kept exactly (a frame axis ends at the
// last frame, the key images of a 3-key map are -1 to 2) and gets the round ticks inside it. Integer axes keep a
// step of at least 1.
AxisTicks AxisFor(const std::optional<cv::Point2d>& fixed, double data_low, double data_high, bool integer) {
  double low = fixed ? fixed->x : data_low;
  double high = fixed ? fixed->y : data_high;
  if (!(low <= high)) low = 0.0, high = 1.0;
  // Data spanning fewer than 5 integers: room for 1-steps, never 0.5.
  if (integer && !fixed && high - low < 4.0) high = low + 4.0;
  AxisTicks ticks = NiceTicks(low, high);
  if (integer && ticks.step < 1.0) ticks = NiceTicks(low, high, 2);
  if (fixed && high > low) {
    std::vector<double> inside;
    const double eps = ticks.step * 1e-9;
    for (double v = std::ceil((low - eps) / ticks.step) * ticks.step; v <= high + eps; v += ticks.step) {
      inside.push_back(v);
    }
    ticks.values = inside;
    ticks.low = low;
    ticks.high = high;
  }
  return ticks;
}

std::string Px(double v) { return FormatFixed(v, 2); }

}  // namespace

SvgPlot::SvgPlot(std::string id, std::string x_label, std::string y_label)
    : id_(std::move(id)), x_label_(std::move(x_label)), y_label_(std::move(y_label)) {}

std::string SvgPlot::Render() const {
  double x_low = std::numeric_limits<double>::infinity(), x_high = -x_low;
  double y_low = x_low, y_high = -x_low;
  for (const PlotSeries& s : series_) {
    for (const auto& segment : s.segments) {
      for (const cv::Point2d& p : segment) {
        if (s.kind != PlotSeries::Kind::kHorizontalRule) x_low = std::min(x_low, p.x), x_high = std::max(x_high, p.x);
        if (s.kind != PlotSeries::Kind::kVerticalRules) y_low = std::min(y_low, p.y), y_high = std::max(y_high, p.y);
      }
    }
  }
  if (!std::isfinite(x_low)) x_low = 0.0, x_high = 1.0;
  if (!std::isfinite(y_low)) y_low = 0.0, y_high = 1.0;
  const AxisTicks xt = AxisFor(x_range_, x_low, x_high, integer_x_);
  const AxisTicks yt = AxisFor(y_range_, y_low, y_high, integer_y_);

  // Room for the legend above and the tick labels and axis titles around the plot area.
  const Box box{64.0, width_ - 16.0, 34.0, height_ - 46.0};
  auto to_x = [&](double x) { return box.left + (x - xt.low) / (xt.high - xt.low) * (box.right - box.left); };
  auto to_y = [&](double y) { return box.bottom - (y - yt.low) / (yt.high - yt.low) * (box.bottom - box.top); };

  std::ostringstream svg;
  svg << "<svg class=\"plot\" id=\"" << HtmlEscape(id_) << "\" viewBox=\"0 0 " << width_ << ' ' << height_
      << "\" width=\"" << width_ << "\" height=\"" << height_ << "\" role=\"img\""
      << " data-x-min=\"" << FormatExact(xt.low) << "\" data-x-max=\"" << FormatExact(xt.high) << "\""
      << " data-y-min=\"" << FormatExact(yt.low) << "\" data-y-max=\"" << FormatExact(yt.high) << "\""
      << " data-left=\"" << Px(box.left) << "\" data-right=\"" << Px(box.right) << "\""
      << " data-top=\"" << Px(box.top) << "\" data-bottom=\"" << Px(box.bottom) << "\">\n";

  // Grid and ticks.
  svg << "<g class=\"axes\" font-size=\"12\" fill=\"#333\">\n";
  for (double v : yt.values) {
    const double y = to_y(v);
    svg << "<line x1=\"" << Px(box.left) << "\" x2=\"" << Px(box.right) << "\" y1=\"" << Px(y) << "\" y2=\"" << Px(y)
        << "\" stroke=\"#e4e4e4\"/>"
        << "<text x=\"" << Px(box.left - 6) << "\" y=\"" << Px(y + 4) << "\" text-anchor=\"end\">"
        << FormatFixed(v, yt.decimals) << "</text>\n";
  }
  for (double v : xt.values) {
    const double x = to_x(v);
    svg << "<line x1=\"" << Px(x) << "\" x2=\"" << Px(x) << "\" y1=\"" << Px(box.bottom) << "\" y2=\""
        << Px(box.bottom + 5) << "\" stroke=\"#333\"/>"
        << "<text x=\"" << Px(x) << "\" y=\"" << Px(box.bottom + 18) << "\" text-anchor=\"middle\">"
        << FormatFixed(v, xt.decimals) << "</text>\n";
  }
  svg << "<rect x=\"" << Px(box.left) << "\" y=\"" << Px(box.top) << "\" width=\"" << Px(box.right - box.left)
      << "\" height=\"" << Px(box.bottom - box.top) << "\" fill=\"none\" stroke=\"#333\"/>\n";
  svg << "<text x=\"" << Px((box.left + box.right) / 2) << "\" y=\"" << Px(height_ - 8.0)
      << "\" text-anchor=\"middle\" font-size=\"13\">" << HtmlEscape(x_label_) << "</text>\n";
  svg << "<text transform=\"translate(16 " << Px((box.top + box.bottom) / 2)
      << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"13\">" << HtmlEscape(y_label_) << "</text>\n";
  svg << "</g>\n";

  // Series, clipped to the plot area so a value outside a fixed range cannot draw over the labels.
  const std::string clip_id = id_ + "-clip";
  svg << "<clipPath id=\"" << HtmlEscape(clip_id) << "\"><rect x=\"" << Px(box.left - 4) << "\" y=\"" << Px(box.top - 4)
      << "\" width=\"" << Px(box.right - box.left + 8) << "\" height=\"" << Px(box.bottom - box.top + 8)
      << "\"/></clipPath>\n";
  for (const PlotSeries& s : series_) {
    const std::string color = HtmlEscape(s.color);
    svg << "<g class=\"series" << (s.css_class.empty() ? "" : " " + HtmlEscape(s.css_class)) << "\" data-name=\""
        << HtmlEscape(s.name) << "\" clip-path=\"url(#" << HtmlEscape(clip_id) << ")\">\n";
    size_t point_number = 0;
    for (size_t k = 0; k < s.segments.size(); ++k) {
      const auto& segment = s.segments[k];
      const std::string extra = k < s.segment_attributes.size() ? " " + s.segment_attributes[k] : "";
      switch (s.kind) {
        case PlotSeries::Kind::kLines: {
          svg << "<polyline" << extra << " fill=\"none\" stroke=\"" << color
              << "\" stroke-width=\"1.5\" stroke-linejoin=\"round\" points=\"";
          for (size_t i = 0; i < segment.size(); ++i) {
            svg << (i ? " " : "") << Px(to_x(segment[i].x)) << ',' << Px(to_y(segment[i].y));
          }
          svg << "\"/>\n";
          break;
        }
        case PlotSeries::Kind::kMarkers:
        case PlotSeries::Kind::kCrosses: {
          for (const cv::Point2d& p : segment) {
            const double x = to_x(p.x), y = to_y(p.y);
            const std::string title =
                point_number < s.point_titles.size() ? HtmlEscape(s.point_titles[point_number]) : std::string();
            ++point_number;
            if (s.kind == PlotSeries::Kind::kMarkers) {
              svg << "<circle" << extra << " cx=\"" << Px(x) << "\" cy=\"" << Px(y) << "\" r=\"" << Px(s.marker_radius)
                  << "\" fill=\"" << color << "\" stroke=\"#fff\" stroke-width=\"0.8\">";
            } else {
              const double r = s.marker_radius;
              svg << "<path" << extra << " data-x=\"" << Px(x) << "\" data-y=\"" << Px(y) << "\" d=\"M" << Px(x - r)
                  << ' ' << Px(y - r) << "L" << Px(x + r) << ' ' << Px(y + r) << "M" << Px(x - r) << ' ' << Px(y + r)
                  << "L" << Px(x + r) << ' ' << Px(y - r) << "\" stroke=\"" << color << "\" stroke-width=\"1.6\">";
            }
            if (!title.empty()) svg << "<title>" << title << "</title>";
            svg << (s.kind == PlotSeries::Kind::kMarkers ? "</circle>\n" : "</path>\n");
          }
          break;
        }
        case PlotSeries::Kind::kHorizontalRule: {
          if (segment.empty()) break;
          const double y = to_y(segment[0].y);
          svg << "<line" << extra << " x1=\"" << Px(box.left) << "\" x2=\"" << Px(box.right) << "\" y1=\"" << Px(y)
              << "\" y2=\"" << Px(y) << "\" stroke=\"" << color
              << "\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"/>\n";
          break;
        }
        case PlotSeries::Kind::kVerticalRules: {
          for (const cv::Point2d& p : segment) {
            const double x = to_x(p.x);
            svg << "<line" << extra << " x1=\"" << Px(x) << "\" x2=\"" << Px(x) << "\" y1=\"" << Px(box.top)
                << "\" y2=\"" << Px(box.bottom) << "\" stroke=\"" << color
                << "\" stroke-width=\"1\" opacity=\"0.6\"/>\n";
          }
          break;
        }
      }
    }
    svg << "</g>\n";
  }

  // Legend: one row above the plot area.
  svg << "<g class=\"legend\" font-size=\"12\">\n";
  double legend_x = box.left;
  for (const PlotSeries& s : series_) {
    if (s.name.empty()) continue;
    const std::string color = HtmlEscape(s.color);
    const double y = 16.0;
    switch (s.kind) {
      case PlotSeries::Kind::kMarkers:
        svg << "<circle cx=\"" << Px(legend_x + 9) << "\" cy=\"" << Px(y) << "\" r=\"4\" fill=\"" << color << "\"/>";
        break;
      case PlotSeries::Kind::kCrosses:
        svg << "<path d=\"M" << Px(legend_x + 5) << ' ' << Px(y - 4) << "l8 8m-8 0l8 -8\" stroke=\"" << color
            << "\" stroke-width=\"1.6\"/>";
        break;
      default:
        svg << "<line x1=\"" << Px(legend_x) << "\" x2=\"" << Px(legend_x + 18) << "\" y1=\"" << Px(y) << "\" y2=\""
            << Px(y) << "\" stroke=\"" << color << "\" stroke-width=\"2\""
            << (s.kind == PlotSeries::Kind::kHorizontalRule ? " stroke-dasharray=\"6 4\"" : "") << "/>";
    }
    svg << "<text x=\"" << Px(legend_x + 24) << "\" y=\"" << Px(y + 4) << "\">" << HtmlEscape(s.name) << "</text>\n";
    // Helvetica-like fonts average a little over half the font size per character.
    legend_x += 24 + 7.0 * s.name.size() + 22;
  }
  svg << "</g>\n</svg>\n";
  return svg.str();
}

}  // namespace vmap::report
