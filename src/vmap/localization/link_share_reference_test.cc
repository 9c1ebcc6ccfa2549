#include "vmap/localization/link_share_reference.h"

#include <cstdlib>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace vmap {
namespace {

// A route of frames along a corridor: what two key images p < q share falls with q - p, as near-duplicates' links
// (one frame apart) verify about twice what key images two or three frames apart do.
std::optional<SharedByKeys> AlongCorridor(int p, int q) {
  const int apart = std::abs(q - p);
  static const SharedByKeys kShared[] = {{1.0, 0}, {0.55, 80}, {0.46, 45}, {0.38, 30}, {0.2, 12}};
  if (apart >= 5) return std::nullopt;
  return kShared[apart];
}

std::vector<std::optional<SharedByKeys>> LinksOf(int positions) {
  std::vector<std::optional<SharedByKeys>> links(positions);
  for (int p = 0; p + 1 < positions; ++p) links[p] = AlongCorridor(p, p + 1);
  return links;
}

TEST(LinkShareReference, AMapSpacedAsTauLinksIsItsOwnReference) {
  std::vector<std::pair<int, int>> compared;
  const auto compare = [&](int p, int q) {
    compared.emplace_back(p, q);
    return AlongCorridor(p, q);
  };
  // The links themselves below tau: nothing compared, each key image's smaller link, as the links alone gave.
  std::vector<std::optional<SharedByKeys>> links = {SharedByKeys{0.3, 40}, SharedByKeys{0.35, 25},
                                                    SharedByKeys{0.32, 33}, std::nullopt};
  EXPECT_EQ(LinkShareReference(links, compare, 0.4, 10), (std::vector<int>{40, 25, 25, 33}));
  EXPECT_TRUE(compared.empty());
}

TEST(LinkShareReference, NearDuplicateNeighboursAreMeasuredAtTheSpacingOfTau) {
  int comparisons = 0;
  const auto compare = [&](int p, int q) {
    ++comparisons;
    return AlongCorridor(p, q);
  };
  // At tau 0.4 two frames apart still reach it (0.46), three do not: the reference is what two apart verify, 45 in
  // place of 80, for every key image with a neighbour two positions on either side.
  EXPECT_EQ(LinkShareReference(LinksOf(6), compare, 0.4, 10), (std::vector<int>{45, 45, 45, 45, 45, 45}));
  EXPECT_EQ(comparisons, 2 * 3 + 1);  // positions 0-2 compare two and three on, 3 only two on (5 is the last)
  // A lower tau reaches three apart: 30.
  EXPECT_EQ(LinkShareReference(LinksOf(6), AlongCorridor, 0.35, 10), (std::vector<int>{30, 30, 30, 30, 30, 30}));
  // The reach bounds the walk; tau above the links' own S walks nowhere.
  EXPECT_EQ(LinkShareReference(LinksOf(6), AlongCorridor, 0.35, 2), (std::vector<int>{45, 45, 45, 45, 45, 45}));
  EXPECT_EQ(LinkShareReference(LinksOf(6), AlongCorridor, 0.6, 10), (std::vector<int>{80, 80, 80, 80, 80, 80}));
}

TEST(LinkShareReference, AMissingLinkEndsTheWalkAndAFailedComparisonToo) {
  std::vector<std::optional<SharedByKeys>> links = LinksOf(6);
  links[2].reset();  // no link between positions 2 and 3
  const std::vector<int> references = LinkShareReference(links, AlongCorridor, 0.4, 10);
  // 0 walks to 2, and 3 to 5; 1 cannot walk past the gap, nor can a walk from behind reach it two on: its links (80)
  // stay its reference, and 4's likewise.
  EXPECT_EQ(references, (std::vector<int>{45, 80, 45, 45, 80, 45}));
  links.assign(4, std::nullopt);
  EXPECT_EQ(LinkShareReference(links, AlongCorridor, 0.4, 10), (std::vector<int>{0, 0, 0, 0}));
  const auto unmatched = [](int, int) { return std::optional<SharedByKeys>(); };
  EXPECT_EQ(LinkShareReference(LinksOf(4), unmatched, 0.4, 10), (std::vector<int>{80, 80, 80, 80}));
}

TEST(LinkShareReference, TheWalksOnThreadsGiveTheSameReferences) {
  for (const double tau : {0.35, 0.4, 0.6}) {
    EXPECT_EQ(LinkShareReference(LinksOf(40), AlongCorridor, tau, 10, 3),
              LinkShareReference(LinksOf(40), AlongCorridor, tau, 10, 1))
        << tau;
  }
  const auto failing = [](int p, int q) -> std::optional<SharedByKeys> {
    if (p == 7) throw std::runtime_error("no features");
    return AlongCorridor(p, q);
  };
  EXPECT_THROW(LinkShareReference(LinksOf(40), failing, 0.4, 10, 2), std::runtime_error);
}

}  // namespace
}  // namespace vmap
