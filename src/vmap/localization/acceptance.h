#pragma once
// When a frame counts as seen at a key image: the acceptance rule of a comparison (Localizer::Compare).
//
// kChance (the default) accepts a comparison whose verified matches are unlikely to have arisen by chance:
// the a-contrario number of false alarms of F on the pair's tentative matches (geometry/chance_model.h), with
// every comparison one frame can make counted as a test (ComparisonsPerFrame), is at most 10^max_log10_nfa. The
// test weighs what the matcher gave (the tentative count), the image size and how tightly the matches fit F, so
// one setting serves ORB and the deep matchers, 320x240 and 1241x376 alike. That says "the same scene"; the
// Localizer adds "the same place" against the map's own links (LocalizerOptions::min_link_share). kCounts is the
// earlier rule: at least min_verified verified matches and S >= min_similarity, whatever the matcher.
// docs/localization-acceptance.md has the derivation and the measurements.

#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/geometry/chance_model.h"
#include "vmap/mapping/key_image_selector.h"

namespace vmap {

enum class AcceptanceRule {
  kChance,  // log10 NFA <= max_log10_nfa
  kCounts,  // verified >= min_verified and S >= min_similarity
};
inline constexpr EnumName<AcceptanceRule> kAcceptanceRuleNames[] = {{AcceptanceRule::kChance, "chance"},
                                                                    {AcceptanceRule::kCounts, "counts"}};
AcceptanceRule ParseAcceptanceRule(const std::string& name);
std::string AcceptanceRuleName(AcceptanceRule rule);

// The chance of a comparison's verified set: ChanceOfFundamental of its F on all its tentative matches
// (PairComparison::correspondences, p0 in the frame of `frame_size`, p1 in the key image of `key_size`),
// `comparisons_per_frame` the tests made for one frame. Unmatched: log10_nfa = +infinity.
ChanceOfMatches ChanceOfComparison(const PairComparison& pair, cv::Size frame_size, cv::Size key_size,
                                   int comparisons_per_frame);

// The most key images one frame is compared with: tracking compares `key`, `lookahead` key images ahead and
// the one behind; when that fails, relocalization verifies `relocalization_candidates` and the best one's two
// neighbours. The frame is accepted when any of them passes, so each is a test of the a-contrario count.
// (Which key images are compared depends on the ranking of descriptors, not on where the matches lie, so the
// chance of the positions is not changed by the choice.)
int ComparisonsPerFrame(int lookahead, int relocalization_candidates);

}  // namespace vmap
