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
  EXPECT_EQ(back.Of<OrbMatcherOptions>().num_features, 1200);
  EXPECT_DOUBLE_EQ(back.Of<OrbMatcherOptions>().scale_factor, 1.3);
  EXPECT_EQ(back.Of<OrbMatcherOptions>().num_levels, 6);
  EXPECT_EQ(back.Of<OrbMatcherOptions>().edge_threshold, 19);
  EXPECT_EQ(back.Of<OrbMatcherOptions>().fast_threshold, 12);
  EXPECT_FALSE(back.Of<OrbMatcherOptions>().cross_check);
  EXPECT_DOUBLE_EQ(back.Of<OrbMatcherOptions>().ratio, 0.8);
  // The rebuilt matcher records the same options.
  EXPECT_EQ(CreateOrbMatcher(back.Of<OrbMatcherOptions>())->DescribeOptionsJson(), matcher->DescribeOptionsJson());
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
  EXPECT_NE(
      message(R"({"type": "orb", "num_features": "many"})").find("num_features must be an integer (it is string)"),
      std::string::npos);
  // Named by its JSON key, as the model's options are.
  EXPECT_NE(message(R"({"type": "orb", "num_features": 0})").find("orb.num_features 0 is outside [1, 100000]"),
            std::string::npos);
}

}  // namespace
}  // namespace vmap
