#include "vmap/localization/heading_continuity.h"

#include <gtest/gtest.h>

namespace vmap {
namespace {

KeyComparison WithHeading(int key, double px, double confidence, double log10_nfa) {
  KeyComparison c;
  c.key = key;
  c.matched = true;
  c.heading.px = px;
  c.heading.confidence = confidence;
  c.log10_nfa = log10_nfa;
  return c;
}

// `n` matches moving by `dx` (frame x minus key image x), `m` more scattered far from it.
TentativeMatches Moving(int n, double dx, int m) {
  TentativeMatches matches;
  for (int i = 0; i < n + m; ++i) {
    const cv::Point2f key_point(100.0f + i, 200.0f);
    const double by = i < n ? dx : dx + 200.0 + 3.0 * i;
    matches.points1.push_back(key_point);
    matches.points0.push_back(key_point + cv::Point2f(static_cast<float>(by), 0.0f));
  }
  return matches;
}

TEST(HeadingContinuity, PredictsByThePreviousFramesHeadingAgainstTheSameKeyImage) {
  HeadingContinuity continuity(GuidedMatchingOptions{});
  FrameComparisons previous([](const ImageFeatures&, int key) { return WithHeading(key, 12.5 * key, 0.9, -20.0); }, 0);
  struct NoFeatures : ImageFeatures {
    int num_features() const override { return 0; }
    cv::Size image_size() const override { return {640, 480}; }
  } frame;
  previous.Begin({});
  previous.Once(frame, 2);
  previous.Once(frame, 4);
  EXPECT_FALSE(continuity.Predicted(2));
  continuity.Remember(previous, /*guess=*/false);
  ASSERT_TRUE(continuity.Predicted(4));
  EXPECT_DOUBLE_EQ(*continuity.Predicted(4), 50.0);
  EXPECT_FALSE(continuity.Predicted(3));
  EXPECT_FALSE(continuity.follows_a_guess());
  continuity.Remember(previous, /*guess=*/true);
  EXPECT_TRUE(continuity.follows_a_guess());
  continuity.Reset();
  EXPECT_FALSE(continuity.Predicted(4));
  EXPECT_FALSE(continuity.follows_a_guess());
}

TEST(HeadingContinuity, HoldsWhenEnoughMatchesMoveAsPredictedAndTheFirstComparisonPassesItsGuards) {
  GuidedMatchingOptions options;
  options.continuity_share = 0.25;
  const HeadingContinuity continuity(options);
  const cv::Size size(640, 480);
  const KeyComparison first = WithHeading(1, 30.0, 0.9, -3.0);
  EXPECT_TRUE(continuity.Holds(first, Moving(30, 30.0, 70), 30.0, size));
  EXPECT_FALSE(continuity.Holds(first, Moving(20, 30.0, 80), 30.0, size));   // a fifth moves so
  EXPECT_FALSE(continuity.Holds(first, Moving(30, 30.0, 70), -60.0, size));  // another prediction
  EXPECT_FALSE(continuity.Holds(first, TentativeMatches(), 30.0, size));
  // The guards: the first comparison's heading mode and its chance.
  EXPECT_FALSE(continuity.Holds(WithHeading(1, 30.0, options.continuity_heading_confidence / 2, -3.0),
                                Moving(30, 30.0, 70), 30.0, size));
  EXPECT_FALSE(continuity.Holds(WithHeading(1, 30.0, 0.9, options.continuity_max_log10_nfa + 1.0), Moving(30, 30.0, 70),
                                30.0, size));
}

}  // namespace
}  // namespace vmap
