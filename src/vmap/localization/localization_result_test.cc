#include "vmap/localization/localization_result.h"

#include <cmath>

#include <gtest/gtest.h>

#include "vmap/localization/key_bracket.h"

namespace vmap {
namespace {

// A controller must not steer by a frame the localizer is lost at or doubts, whatever its heading says.
TEST(LocalizationGuidance, SaysNotToSteerByALostOrUncertainFrame) {
  LocalizationResult r;
  r.key = 3;
  r.next_key = 4;
  r.heading_px = 12.0;
  r.status = LocalizationStatus::kTracking;
  EXPECT_EQ(LocalizationGuidance(r), "heading only: no pose");
  EXPECT_TRUE(MaySteerBy(r));
  r.status = LocalizationStatus::kRelocalized;
  EXPECT_TRUE(MaySteerBy(r));
  r.status = LocalizationStatus::kUncertain;
  EXPECT_EQ(LocalizationGuidance(r), "none: position uncertain");
  r.withheld_by = Withholding::kStalledTracker;
  EXPECT_EQ(LocalizationGuidance(r), "none: position uncertain (stalled tracker)");
  EXPECT_FALSE(MaySteerBy(r));
  r.withheld_by = Withholding::kNone;
  EXPECT_FALSE(MaySteerBy(r));
  r.status = LocalizationStatus::kLost;
  EXPECT_EQ(LocalizationGuidance(r), "none: lost");
  EXPECT_FALSE(MaySteerBy(r));
  r.status = LocalizationStatus::kTracking;
  r.heading_px = std::nan("");
  EXPECT_EQ(LocalizationGuidance(r), "none");
  EXPECT_FALSE(MaySteerBy(r));
  EXPECT_EQ(LocalizationStatusName(LocalizationStatus::kUncertain), "uncertain");
}

TEST(KeysAround, FollowsTheInputIndices) {
  VisualMap map;
  for (int s : {0, 10, 20}) {
    KeyImage k;
    k.source_index = s;
    map.key_images.push_back(k);
  }
  EXPECT_EQ(KeysAround(map, 5), std::make_pair(0, 1));
  EXPECT_EQ(KeysAround(map, 10), std::make_pair(1, 1));
  EXPECT_EQ(KeysAround(map, 25), std::make_pair(2, -1));
}

}  // namespace
}  // namespace vmap
