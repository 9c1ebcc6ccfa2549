#include "vmap/neural/xfeat/xfeat_options.h"

#include <gtest/gtest.h>

#include "vmap/features/matcher_options_json.h"

namespace vmap {
namespace {

// What the XFeat matcher records in map.json (xfeat_matcher.cc) rebuilds its options, so that `vmap
// localize` runs on its maps.
TEST(MatcherOptionsFromJson, ReadsXfeatOptions) {
  const MatcherOptions xfeat = MatcherOptionsFromJson(
      R"({"type": "xfeat", "weights": "/nowhere/xfeat.pt", "weights_layout": "folded", "device": "cpu",
          "top_k": 2048, "detection_threshold": 0.04, "min_similarity": 0.8, "threads": 1})",
      "map.json");
  EXPECT_EQ(xfeat.type, "xfeat");
  EXPECT_EQ(xfeat.Of<XfeatMatcherOptions>().weights, "");
  EXPECT_EQ(xfeat.Of<XfeatMatcherOptions>().top_k, 2048);
  EXPECT_DOUBLE_EQ(xfeat.Of<XfeatMatcherOptions>().detection_threshold, 0.04);
  EXPECT_DOUBLE_EQ(xfeat.Of<XfeatMatcherOptions>().min_similarity, 0.8);
}

}  // namespace
}  // namespace vmap
