#include "vmap/localization/route.h"

#include <gtest/gtest.h>

#include "vmap/core/error.h"

namespace vmap {
namespace {

// Key images 0..5 of one teach run; link 2 (key 2 -> 3) has no F (matching failed), link 4 (key 4 -> 5) is
// weak, link 1 is below tau (with an F as good as any).
VisualMap ChainMap() {
  VisualMap map;
  for (int k = 0; k < 6; ++k) {
    KeyImage key;
    key.frame_index = key.source_index = 10 * k;
    map.key_images.push_back(key);
  }
  for (int k = 0; k < 5; ++k) {
    Link link;
    link.from_key = k;
    link.to_key = k + 1;
    link.num_verified = k == 4 ? 12 : 150;
    link.similarity = 0.6;
    link.has_fundamental = k != 2;
    link.below_tau = k == 1;
    map.links.push_back(link);
  }
  return map;
}

std::string ErrorOf(const VisualMap& map, int from, int to) {
  try {
    PlanRoute(map, from, to);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Route, ForwardsIsTheTeachRunsOrderAndWarnsAboutLinksWithoutFOrWithLittleEvidence) {
  const Route route = PlanRoute(ChainMap(), 1, 5);
  EXPECT_EQ(route.keys, (std::vector<int>{1, 2, 3, 4, 5}));
  ASSERT_EQ(route.steps.size(), 4u);
  for (size_t i = 0; i < route.steps.size(); ++i) {
    EXPECT_FALSE(route.steps[i].backwards);
    EXPECT_EQ(route.steps[i].link, static_cast<int>(i) + 1);
  }
  EXPECT_TRUE(route.steps[1].unverified);
  EXPECT_FALSE(route.steps[0].unverified);
  ASSERT_EQ(route.warnings.size(), 2u);
  EXPECT_NE(route.warnings[0].find("link 2"), std::string::npos) << route.warnings[0];
  EXPECT_NE(route.warnings[1].find("link 4 (key 4 -> 5) is verified by 12 matches only"), std::string::npos)
      << route.warnings[1];
  EXPECT_EQ(PlanRoute(ChainMap(), 3, 4).warnings.size(), 0u);
}

TEST(Route, BackwardsOnlyOverVerifiedLinks) {
  const Route route = PlanRoute(ChainMap(), 2, 0);
  EXPECT_EQ(route.keys, (std::vector<int>{2, 1, 0}));
  for (const RouteStep& s : route.steps) EXPECT_TRUE(s.backwards);
  EXPECT_TRUE(route.warnings.empty());
  // Across the link without F, and over the weak one, there is no way back; the one below tau is fine.
  const std::string unverified = ErrorOf(ChainMap(), 4, 1);
  EXPECT_NE(unverified.find("no route from key image 4 to key image 1"), std::string::npos) << unverified;
  EXPECT_NE(unverified.find("link 2 (key 2 -> 3) is not verified"), std::string::npos) << unverified;
  const std::string weak = ErrorOf(ChainMap(), 5, 4);
  EXPECT_NE(weak.find("verified by 12 matches only"), std::string::npos) << weak;
  RouteOptions lenient;
  lenient.min_backward_verified = 10;
  EXPECT_EQ(PlanRoute(ChainMap(), 5, 4, lenient).keys, (std::vector<int>{5, 4}));
}

TEST(Route, OneKeyImageAndBadKeyImages) {
  const Route route = PlanRoute(ChainMap(), 3, 3);
  EXPECT_EQ(route.keys, std::vector<int>{3});
  EXPECT_TRUE(route.steps.empty());
  EXPECT_NE(ErrorOf(ChainMap(), 0, 6).find("key image 6 does not exist; the map has key images 0 to 5"),
            std::string::npos);
  EXPECT_NE(ErrorOf(ChainMap(), -1, 2).find("key image -1 does not exist"), std::string::npos);
  RouteOptions bad;
  bad.min_backward_verified = 3;
  EXPECT_THROW(PlanRoute(ChainMap(), 0, 1, bad), InputError);
}

}  // namespace
}  // namespace vmap
