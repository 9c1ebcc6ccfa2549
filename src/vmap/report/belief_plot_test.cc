// The localization report's plot of the belief over the route.
#include "vmap/report/belief_plot.h"

#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "vmap/testing/report_test_util.h"

namespace vmap::report {
namespace {

LocalizationResult Frame(int index, int key, std::vector<std::pair<int, double>> belief) {
  LocalizationResult r;
  r.frame_index = index;
  r.key = key;
  r.status = LocalizationStatus::kTracking;
  r.belief = std::move(belief);
  return r;
}

// Each frame's belief is drawn at its key images, darker where it holds more, beside the frame's key image.
TEST(BeliefPlot, DrawsEachFramesBeliefAtItsKeyImagesWithItsMass) {
  LocalizationRun run;
  run.frames = {Frame(0, 2, {{1, 0.2}, {2, 0.8}}), Frame(1, 3, {{3, 1.0}}), Frame(2, -1, {})};
  const std::string svg = BeliefPlot(run, 10);
  ASSERT_FALSE(svg.empty());
  EXPECT_NE(svg.find("id=\"belief-plot\""), std::string::npos);
  const report_test::PlotAxes axes = report_test::ParsePlotAxes(svg);
  const std::vector<cv::Point2d> mass = report_test::CircleCentres(svg, "data-mass", axes);
  ASSERT_EQ(mass.size(), 3u);
  const cv::Point2d expected[] = {{0, 1}, {0, 2}, {1, 3}};
  for (size_t i = 0; i < mass.size(); ++i) {
    EXPECT_NEAR(mass[i].x, expected[i].x, 0.05) << i;
    EXPECT_NEAR(mass[i].y, expected[i].y, 0.05) << i;
  }
  const std::vector<std::string> masses = report_test::AttributeValues(svg, "data-mass");
  ASSERT_EQ(masses.size(), 3u);
  EXPECT_NEAR(std::atof(masses[0].c_str()), 0.2, 1e-9);
  EXPECT_NEAR(std::atof(masses[2].c_str()), 1.0, 1e-9);
  const std::vector<std::string> opacities = report_test::AttributeValues(svg, "fill-opacity");
  ASSERT_EQ(opacities.size(), 3u);
  EXPECT_LT(std::atof(opacities[0].c_str()), std::atof(opacities[1].c_str())) << "more belief, darker";
  // The frames' key images (frame 2 has none), in orange (the legend's marker too).
  EXPECT_NE(svg.find("belief-key"), std::string::npos);
  int keys_drawn = 0;
  for (const cv::Point2d& p : report_test::CircleCentres(svg, "fill=\"#e07b00\"", axes)) {
    keys_drawn += (std::abs(p.x - 0) < 0.05 && std::abs(p.y - 2) < 0.05) ||
                  (std::abs(p.x - 1) < 0.05 && std::abs(p.y - 3) < 0.05);
  }
  EXPECT_EQ(keys_drawn, 2);
}

TEST(BeliefPlot, ARunWithoutARecordedBeliefHasNoPlot) {
  LocalizationRun run;
  run.frames = {Frame(0, 2, {}), Frame(1, 3, {})};
  EXPECT_EQ(BeliefPlot(run, 10), "");
}

}  // namespace
}  // namespace vmap::report
