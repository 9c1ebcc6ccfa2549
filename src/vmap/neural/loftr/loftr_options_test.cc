#include "vmap/neural/loftr/loftr_options.h"

#include <gtest/gtest.h>

#include "vmap/features/matcher_options_json.h"

namespace vmap {
namespace {

TEST(MatcherOptionsFromJson, ReadsLoftrOptionsAndDropsAWeightsFileThatIsNotHere) {
  const MatcherOptions options = MatcherOptionsFromJson(
      R"({"type": "loftr", "model": "outdoor", "weights": "/nowhere/outdoor_ds.ckpt", "device": "cpu",
          "longest_side": 480, "threshold": 0.3, "threads": 2, "coarse_stride": 8})",
      "map.json");
  EXPECT_EQ(options.type, "loftr");
  EXPECT_EQ(options.Of<LoftrMatcherOptions>().model, "outdoor");
  EXPECT_EQ(options.Of<LoftrMatcherOptions>().weights, "");
  EXPECT_EQ(options.Of<LoftrMatcherOptions>().longest_side, 480);
  EXPECT_DOUBLE_EQ(options.Of<LoftrMatcherOptions>().threshold, 0.3);
  EXPECT_EQ(options.Of<LoftrMatcherOptions>().num_threads, 2);
}

}  // namespace
}  // namespace vmap
