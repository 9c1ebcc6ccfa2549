#include "vmap/features/matcher_options_json.h"

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/features/orb_matcher.h"

namespace vmap {
namespace {

TEST(MatcherOptionsFromJson, RebuildsTheOrbOptionsAMapRecorded) {
  OrbMatcherOptions orb;
  orb.num_features = 1200;
  orb.scale_factor = 1.3;
  orb.num_levels = 6;
  orb.edge_threshold = 19;
  orb.fast_threshold = 12;
  orb.cross_check = false;
  orb.ratio = 0.8;
  const auto matcher = CreateOrbMatcher(orb);
  const MatcherOptions back = MatcherOptionsFromJson(matcher->DescribeOptionsJson(), "map.json");
  EXPECT_EQ(back.type, "orb");
  EXPECT_EQ(back.orb.num_features, 1200);
  EXPECT_DOUBLE_EQ(back.orb.scale_factor, 1.3);
  EXPECT_EQ(back.orb.num_levels, 6);
  EXPECT_EQ(back.orb.edge_threshold, 19);
  EXPECT_EQ(back.orb.fast_threshold, 12);
  EXPECT_FALSE(back.orb.cross_check);
  EXPECT_DOUBLE_EQ(back.orb.ratio, 0.8);
  // The rebuilt matcher records the same options.
  EXPECT_EQ(CreateOrbMatcher(back.orb)->DescribeOptionsJson(), matcher->DescribeOptionsJson());
}

TEST(MatcherOptionsFromJson, ReadsLoftrOptionsAndDropsAWeightsFileThatIsNotHere) {
  const MatcherOptions options = MatcherOptionsFromJson(
      R"({"type": "loftr", "model": "outdoor", "weights": "/nowhere/outdoor_ds.ckpt", "device": "cpu",
          "longest_side": 480, "threshold": 0.3, "threads": 2, "coarse_stride": 8})",
      "map.json");
  EXPECT_EQ(options.type, "loftr");
  EXPECT_EQ(options.loftr.model, "outdoor");
  EXPECT_EQ(options.loftr.weights, "");
  EXPECT_EQ(options.loftr.longest_side, 480);
  EXPECT_DOUBLE_EQ(options.loftr.threshold, 0.3);
  EXPECT_EQ(options.loftr.num_threads, 2);
}

// What XFeat and ALIKED matchers record in map.json (neural/xfeat_matcher.cc, aliked_matcher.cc) rebuilds
// their options, so that `vmap localize` runs on their maps.
TEST(MatcherOptionsFromJson, ReadsXfeatAndAlikedOptions) {
  const MatcherOptions xfeat = MatcherOptionsFromJson(
      R"({"type": "xfeat", "weights": "/nowhere/xfeat.pt", "weights_layout": "folded", "device": "cpu",
          "top_k": 2048, "detection_threshold": 0.04, "min_similarity": 0.8, "threads": 1})",
      "map.json");
  EXPECT_EQ(xfeat.type, "xfeat");
  EXPECT_EQ(xfeat.xfeat.weights, "");
  EXPECT_EQ(xfeat.xfeat.top_k, 2048);
  EXPECT_DOUBLE_EQ(xfeat.xfeat.detection_threshold, 0.04);
  EXPECT_DOUBLE_EQ(xfeat.xfeat.min_similarity, 0.8);
  const MatcherOptions aliked = MatcherOptionsFromJson(
      R"({"type": "aliked", "model": "aliked-n16", "weights": "", "device": "cpu", "top_k": 0,
          "score_threshold": 0.3, "max_keypoints": 3000, "min_similarity": 0.9, "longest_side": 640,
          "threads": 1, "nms_radius": 2, "sub_pixel": true})",
      "map.json");
  EXPECT_EQ(aliked.type, "aliked");
  EXPECT_EQ(aliked.aliked.model, "n16");
  EXPECT_EQ(aliked.aliked.top_k, 0);
  EXPECT_DOUBLE_EQ(aliked.aliked.score_threshold, 0.3);
  EXPECT_EQ(aliked.aliked.max_keypoints, 3000);
  EXPECT_DOUBLE_EQ(aliked.aliked.min_similarity, 0.9);
  EXPECT_EQ(aliked.aliked.longest_side, 640);
}

TEST(MatcherOptionsFromJson, UnknownOrMissingMatchersAreClearErrors) {
  auto message = [](const std::string& json) {
    try {
      MatcherOptionsFromJson(json, "m/map.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(R"({"type": "sift"})").find("built with the matcher 'sift'"), std::string::npos);
  EXPECT_NE(message("{}").find("does not record its matcher"), std::string::npos);
  EXPECT_NE(message(R"({"type": "orb", "num_features": "many"})").find("num_features has the wrong type"),
            std::string::npos);
  EXPECT_NE(message(R"({"type": "orb", "num_features": 0})").find("--orb-features"), std::string::npos);
}

}  // namespace
}  // namespace vmap
