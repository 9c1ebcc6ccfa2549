#include "vmap/localization/lagging_start.h"

#include <gtest/gtest.h>

namespace vmap {
namespace {

TEST(LaggingStart, LagsWhenTheTrackerMovedOnAtMostOneKeyImageOverItsFrames) {
  LaggingStart pace(/*frames=*/3, /*start_frames=*/10);
  pace.Remember(4);
  pace.Remember(4);
  EXPECT_FALSE(pace.Lags());  // two frames: too few to tell
  pace.Remember(5);
  EXPECT_TRUE(pace.Lags());
  pace.Remember(6);  // 4, 5, 6: two key images on
  EXPECT_FALSE(pace.Lags());
  pace.Remember(5);  // 5, 6, 5: none
  EXPECT_TRUE(pace.Lags());
  pace.Remember(3);  // 6, 5, 3: back, a step back's to judge
  EXPECT_FALSE(pace.Lags());
}

TEST(LaggingStart, OnlyOverTheRunsFirstFramesAndNotAcrossALostEstimate) {
  LaggingStart pace(2, /*start_frames=*/3);
  pace.Remember(4);
  pace.Remember(-1);  // no estimate: the pace is forgotten
  pace.Remember(4);
  EXPECT_FALSE(pace.Lags());
  pace.Remember(4);
  EXPECT_FALSE(pace.Lags());  // the fourth frame after the start: past start_frames
  pace.Reset();
  pace.Remember(4);
  pace.Remember(4);
  EXPECT_TRUE(pace.Lags());
  EXPECT_FALSE(LaggingStart(0, 10).Lags());
}

}  // namespace
}  // namespace vmap
