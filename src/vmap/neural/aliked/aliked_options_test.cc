#include "vmap/neural/aliked/aliked_options.h"

#include <gtest/gtest.h>

#include "vmap/features/matcher_options_json.h"

namespace vmap {
namespace {

// What the ALIKED matcher records in map.json (aliked_matcher.cc) rebuilds its options, so that `vmap
// localize` runs on its maps.
TEST(MatcherOptionsFromJson, ReadsAlikedOptions) {
  const MatcherOptions aliked = MatcherOptionsFromJson(
      R"({"type": "aliked", "model": "aliked-n16", "weights": "", "device": "cpu", "top_k": 0,
          "score_threshold": 0.3, "max_keypoints": 3000, "min_similarity": 0.9, "longest_side": 640,
          "threads": 1, "nms_radius": 2, "sub_pixel": true})",
      "map.json");
  EXPECT_EQ(aliked.type, "aliked");
  EXPECT_EQ(aliked.Of<AlikedMatcherOptions>().model, "n16");
  EXPECT_EQ(aliked.Of<AlikedMatcherOptions>().top_k, 0);
  EXPECT_DOUBLE_EQ(aliked.Of<AlikedMatcherOptions>().score_threshold, 0.3);
  EXPECT_EQ(aliked.Of<AlikedMatcherOptions>().max_keypoints, 3000);
  EXPECT_DOUBLE_EQ(aliked.Of<AlikedMatcherOptions>().min_similarity, 0.9);
  EXPECT_EQ(aliked.Of<AlikedMatcherOptions>().longest_side, 640);
}

}  // namespace
}  // namespace vmap
