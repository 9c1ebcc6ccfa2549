#pragma once
// Line and marker plots written as inline SVG (axes, ticks at round numbers, labels, legend), so that the
// report needs no plotting library and no script.
//
// The <svg> element carries its axis ranges and plot-area box as data-* attributes, so the drawn points can
// be mapped back to data values (the tests do exactly that).

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap::report {

// The reports' palette: one colour per meaning across the map, sweep and localization reports.
inline constexpr const char* kBlue = "#1f77b4";
inline constexpr const char* kOrange = "#e07b00";
inline constexpr const char* kGreen = "#2a9d3a";
inline constexpr const char* kRed = "#d62728";
inline constexpr const char* kGrey = "#8a8a8a";

// Tick positions at 1, 2 or 5 times a power of ten covering [low, high] with about `target` ticks.
struct AxisTicks {
  double low = 0.0;  // the axis range: the first and last tick
  double high = 1.0;
  double step = 0.1;
  std::vector<double> values;
  int decimals = 1;  // digits after the point that tell the ticks apart
};
AxisTicks NiceTicks(double low, double high, int target = 6);

struct PlotSeries {
  enum class Kind {
    kLines,           // each segment is a polyline
    kMarkers,         // every point is a circle
    kCrosses,         // every point is an x
    kHorizontalRule,  // one dashed line across the plot at points[0].y of the first segment
    kVerticalRules,   // a thin line across the plot at each point's x
  };
  Kind kind = Kind::kLines;
  std::string name;  // legend text; empty: not in the legend
  std::string color = "#1f77b4";
  std::string css_class;  // class of the series' <g>, for tests and styling
  std::vector<std::vector<cv::Point2d>> segments;
  std::vector<std::string> segment_attributes;  // optional raw attributes per segment (already escaped)
  std::vector<std::string> point_titles;        // optional tooltip per point (markers only), plain text
  double marker_radius = 3.5;
};

class SvgPlot {
 public:
  SvgPlot(std::string id, std::string x_label, std::string y_label);

  void SetSize(int width, int height) {
    width_ = width;
    height_ = height;
  }
  // Fixes an axis range instead of fitting it to the data (it still widens to round ticks).
  void SetXRange(double low, double high) { x_range_ = cv::Point2d(low, high); }
  void SetYRange(double low, double high) { y_range_ = cv::Point2d(low, high); }
  // Integer axes (frame index, number of key images) never get fractional ticks.
  void SetIntegerX(bool integer) { integer_x_ = integer; }
  void SetIntegerY(bool integer) { integer_y_ = integer; }

  void Add(PlotSeries series) { series_.push_back(std::move(series)); }

  // The <svg> element (no XML prolog: it is meant to be inlined in HTML).
  std::string Render() const;

 private:
  std::string id_, x_label_, y_label_;
  int width_ = 960, height_ = 360;
  std::optional<cv::Point2d> x_range_, y_range_;
  bool integer_x_ = false, integer_y_ = false;
  std::vector<PlotSeries> series_;
};

}  // namespace vmap::report
