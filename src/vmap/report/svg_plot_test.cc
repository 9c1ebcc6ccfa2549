#include "vmap/report/svg_plot.h"

#include <cmath>

#include <gtest/gtest.h>

#include "vmap/testing/report_test_util.h"

namespace vmap::report {
namespace {

bool IsNiceStep(double step) {
  const double magnitude = std::pow(10.0, std::floor(std::log10(step) + 1e-9));
  const double fraction = step / magnitude;
  return std::abs(fraction - 1) < 1e-9 || std::abs(fraction - 2) < 1e-9 || std::abs(fraction - 5) < 1e-9;
}

TEST(NiceTicksTest, CoversTheRangeWithRoundSteps) {
  const AxisTicks unit = NiceTicks(0.0, 0.93);
  EXPECT_DOUBLE_EQ(unit.low, 0.0);
  EXPECT_NEAR(unit.high, 1.0, 1e-12);
  EXPECT_NEAR(unit.step, 0.2, 1e-12);
  EXPECT_EQ(unit.values.size(), 6u);
  EXPECT_EQ(unit.decimals, 1);
  for (auto [low, high] : {std::pair{3.0, 327.0}, {-0.013, 0.0021}, {1e5, 1.7e6}, {0.1, 0.9}}) {
    const AxisTicks t = NiceTicks(low, high);
    EXPECT_TRUE(IsNiceStep(t.step)) << t.step;
    EXPECT_LE(t.low, low);
    EXPECT_GE(t.high, high);
    EXPECT_GE(t.values.size(), 3u);
    EXPECT_LE(t.values.size(), 12u);
  }
}

TEST(NiceTicksTest, SingleValueStillGetsAnAxis) {
  const AxisTicks t = NiceTicks(5.0, 5.0);
  EXPECT_LT(t.low, 5.0);
  EXPECT_GT(t.high, 5.0);
}

TEST(SvgPlotTest, PlottedPointsMapBackToTheData) {
  SvgPlot plot("test-plot", "x", "y");
  PlotSeries line;
  line.segments = {{{0, 0.1}, {3, 0.8}, {7, 0.55}}, {{8, 1.0}, {12, 0.3}}};
  line.segment_attributes = {"data-part=\"a\"", "data-part=\"b\""};
  plot.Add(line);
  PlotSeries dots;
  dots.kind = PlotSeries::Kind::kMarkers;
  dots.segments = {{{12, 0.3}}};
  dots.segment_attributes = {"data-dot=\"1\""};
  plot.Add(dots);
  const std::string svg = plot.Render();
  const report_test::PlotAxes axes = report_test::ParsePlotAxes(svg);
  const auto a = report_test::PolylinePoints(svg, "data-part=\"a\"", axes);
  const auto b = report_test::PolylinePoints(svg, "data-part=\"b\"", axes);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_NEAR(a[1].x, 3, 0.05);
  EXPECT_NEAR(a[1].y, 0.8, 0.005);
  EXPECT_NEAR(b[1].x, 12, 0.05);
  EXPECT_NEAR(b[1].y, 0.3, 0.005);
  const auto dot = report_test::CircleCentres(svg, "data-dot=", axes);
  ASSERT_EQ(dot.size(), 1u);
  EXPECT_NEAR(dot[0].x, 12, 0.05);
  EXPECT_NEAR(dot[0].y, 0.3, 0.005);
  // The axes round outwards to ticks.
  EXPECT_LE(axes.x_min, 0);
  EXPECT_GE(axes.x_max, 12);
}

// The key plot of a 3-key map (keys -1 to 2, fixed) showed -1 to 3: the padding of a short integer range is for
// ranges fitted to the data only.
TEST(SvgPlotTest, AFixedIntegerRangeIsNotPadded) {
  SvgPlot fixed("fixed", "frame", "key");
  fixed.SetIntegerY(true);
  fixed.SetYRange(-1.0, 2.0);
  PlotSeries keys;
  keys.segments = {{{0, 0}, {5, 1}, {9, 2}}};
  fixed.Add(keys);
  const report_test::PlotAxes fixed_axes = report_test::ParsePlotAxes(fixed.Render());
  EXPECT_EQ(fixed_axes.y_min, -1.0);
  EXPECT_EQ(fixed_axes.y_max, 2.0);
  SvgPlot one("one", "frame", "key");
  one.SetIntegerY(true);
  one.SetYRange(0.0, 1.0);
  one.Add(keys);
  const std::string one_svg = one.Render();
  EXPECT_EQ(report_test::ParsePlotAxes(one_svg).y_max, 1.0);
  EXPECT_EQ(one_svg.find(">0.5<"), std::string::npos) << "an integer axis has no half steps";
  // Fitted to the data, a short integer range still gets room for whole steps.
  SvgPlot fitted("fitted", "frame", "key");
  fitted.SetIntegerY(true);
  fitted.Add(keys);
  const report_test::PlotAxes fitted_axes = report_test::ParsePlotAxes(fitted.Render());
  EXPECT_EQ(fitted_axes.y_min, 0.0);
  EXPECT_EQ(fitted_axes.y_max, 4.0);
}

TEST(SvgPlotTest, EscapesLabelsAndNames) {
  SvgPlot plot("p", "x <frames>", "y & \"S\"");
  PlotSeries line;
  line.name = "<script>";
  line.segments = {{{0, 0}, {1, 1}}};
  plot.Add(line);
  const std::string svg = plot.Render();
  EXPECT_EQ(svg.find("<script>"), std::string::npos);
  EXPECT_NE(svg.find("&lt;script&gt;"), std::string::npos);
  EXPECT_NE(svg.find("x &lt;frames&gt;"), std::string::npos);
  EXPECT_NE(svg.find("y &amp; &quot;S&quot;"), std::string::npos);
}

}  // namespace
}  // namespace vmap::report
