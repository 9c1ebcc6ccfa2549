#include "vmap/localization/frame_comparisons.h"

#include <atomic>
#include <vector>

#include <gtest/gtest.h>

namespace vmap {
namespace {

class NoFeatures : public ImageFeatures {
 public:
  int num_features() const override { return 0; }
  cv::Size image_size() const override { return {640, 480}; }
};

KeyComparison Made(int key, int verified) {
  KeyComparison c;
  c.key = key;
  c.matched = true;
  c.num_verified = verified;
  return c;
}

TEST(FrameComparisons, EachKeyImageIsComparedOnceAFrameAndRecordedInTheOrderAsked) {
  std::atomic<int> calls{0};
  FrameComparisons comparisons(
      [&](const ImageFeatures&, int key) {
        ++calls;
        return Made(key, 10 * key);
      },
      0);
  const NoFeatures frame;
  comparisons.Begin({});
  EXPECT_EQ(comparisons.Once(frame, 3).num_verified, 30);
  EXPECT_EQ(comparisons.Once(frame, 1).num_verified, 10);
  EXPECT_EQ(comparisons.Once(frame, 3).num_verified, 30);
  EXPECT_EQ(calls, 2);
  ASSERT_EQ(comparisons.size(), 2u);
  EXPECT_EQ(comparisons[0].comparison.key, 3);
  EXPECT_EQ(comparisons[1].comparison.key, 1);
  // A new frame compares again.
  comparisons.Begin({});
  EXPECT_EQ(comparisons.size(), 0u);
  comparisons.Once(frame, 3);
  EXPECT_EQ(calls, 3);
}

TEST(FrameComparisons, ComparisonsMadeAheadAreTakenOnlyWhenAsked) {
  int calls = 0;
  FrameComparisons comparisons(
      [&](const ImageFeatures&, int key) {
        ++calls;
        return Made(key, 1);
      },
      0);
  const NoFeatures frame;
  comparisons.Begin({Made(5, 77), Made(6, 88)});
  EXPECT_EQ(comparisons.size(), 0u);  // made ahead, not asked for yet
  EXPECT_EQ(comparisons.Once(frame, 6).num_verified, 88);
  EXPECT_EQ(comparisons.Once(frame, 2).num_verified, 1);
  EXPECT_EQ(calls, 1);
  ASSERT_EQ(comparisons.size(), 2u);
  EXPECT_EQ(comparisons[0].comparison.key, 6);
}

TEST(FrameComparisons, ASecondComparisonReplacesTheFirstAsWeighed) {
  FrameComparisons comparisons([](const ImageFeatures&, int key) { return Made(key, 4); }, 0);
  const NoFeatures frame;
  comparisons.Begin({});
  comparisons.Once(frame, 2);
  comparisons.Once(frame, 7);
  comparisons.Replace(Made(7, 40));
  ASSERT_EQ(comparisons.size(), 2u);
  EXPECT_EQ(comparisons[1].comparison.num_verified, 40);
  EXPECT_TRUE(comparisons[1].weighed);
  EXPECT_FALSE(comparisons[0].weighed);
  EXPECT_EQ(comparisons.Once(frame, 7).num_verified, 40);
}

TEST(FrameComparisons, MadeMeanwhileOnHelpersGivesWhatComparingInTurnGives) {
  const auto compare = [](const ImageFeatures&, int key) { return Made(key, key * key); };
  FrameComparisons in_turn(compare, 0), meanwhile(compare, 2);
  const NoFeatures frame;
  for (int f = 0; f < 20; ++f) {
    in_turn.Begin({});
    meanwhile.Begin({});
    const std::vector<int> keys = {f % 7, 3, 9, f % 5 + 10};
    meanwhile.Meanwhile(frame, keys);
    for (const int key : {9, f % 7, 12, 3}) {
      EXPECT_EQ(in_turn.Once(frame, key).num_verified, meanwhile.Once(frame, key).num_verified);
    }
    meanwhile.Finish();
    ASSERT_EQ(in_turn.size(), meanwhile.size());
    for (size_t i = 0; i < in_turn.size(); ++i) EXPECT_EQ(in_turn[i].comparison.key, meanwhile[i].comparison.key);
  }
}

}  // namespace
}  // namespace vmap
