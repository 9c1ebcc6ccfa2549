// The summary of a simulation's trials: what it says when trials lack a figure.

#include "vmap/simulation/closed_loop.h"

#include <cmath>

#include <gtest/gtest.h>

namespace vmap {
namespace {

TrialResult Trial(double lateral_rms_second_half, bool success) {
  TrialResult trial;
  trial.lateral_rms_second_half = lateral_rms_second_half;
  trial.success = success;
  trial.final_error = 0.05;
  return trial;
}

TEST(SimulationSummary, AveragesTheSecondHalfOverTheTrialsThatReachedIt) {
  const SimulationSummary summary = Summarize({Trial(0.04, true), Trial(NAN, false), Trial(0.2, true)});
  EXPECT_DOUBLE_EQ(summary.mean_lateral_rms_second_half, 0.12);
  EXPECT_DOUBLE_EQ(summary.worst_lateral_rms_second_half, 0.2);
  EXPECT_DOUBLE_EQ(summary.share_converged, 1.0 / 3.0);  // a trial that never reached the second half did not converge
  EXPECT_EQ(summary.successes, 2);
}

// A route too short for samples past its half: no figure, rather than 0 m that reads as a perfect run.
TEST(SimulationSummary, NoTrialInTheSecondHalfGivesNoFigure) {
  const SimulationSummary summary = Summarize({Trial(NAN, true), Trial(NAN, true)});
  EXPECT_TRUE(std::isnan(summary.mean_lateral_rms_second_half));
  EXPECT_TRUE(std::isnan(summary.worst_lateral_rms_second_half));
  EXPECT_EQ(summary.share_converged, 0.0);
}

}  // namespace
}  // namespace vmap
