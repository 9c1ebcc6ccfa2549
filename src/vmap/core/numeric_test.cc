#include "vmap/core/numeric.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace vmap {

TEST(Numeric, MedianOfOddAndEvenCountsAndOfNothing) {
  EXPECT_DOUBLE_EQ(Median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_DOUBLE_EQ(Median({3.0, 1.0, 2.0, 10.0}), 2.5);
  EXPECT_DOUBLE_EQ(Median({}), 0.0);
  EXPECT_TRUE(std::isnan(MedianOrNan({})));
  EXPECT_DOUBLE_EQ(MedianOrNan({4.0}), 4.0);
}

TEST(Numeric, FiniteSummariesLeaveNanAndInfinityOut) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  EXPECT_DOUBLE_EQ(MedianOfFinite({nan, 1.0, inf, 3.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(MeanOfFinite({nan, 1.0, -inf, 3.0}), 2.0);
  EXPECT_TRUE(std::isnan(MedianOfFinite({nan, inf})));
  EXPECT_TRUE(std::isnan(MeanOfFinite({})));
}

TEST(Numeric, ShareBelowIsStrict) {
  EXPECT_DOUBLE_EQ(ShareBelow({1.0, 2.0, 3.0, 4.0}, 3.0), 0.5);
  EXPECT_TRUE(std::isnan(ShareBelow({}, 3.0)));
}

}  // namespace vmap
