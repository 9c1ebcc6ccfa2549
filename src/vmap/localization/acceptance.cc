#include "vmap/localization/acceptance.h"

#include <vector>

namespace vmap {

AcceptanceRule ParseAcceptanceRule(const std::string& name) {
  return ParseEnum(kAcceptanceRuleNames, name, "acceptance rule");
}

std::string AcceptanceRuleName(AcceptanceRule rule) { return EnumToName(kAcceptanceRuleNames, rule); }

ChanceOfMatches ChanceOfComparison(const PairComparison& pair, cv::Size frame_size, cv::Size key_size,
                                   int comparisons_per_frame) {
  if (!pair.matched) return {};
  std::vector<cv::Point2f> frame_points, key_points;
  SplitCorrespondences(pair.correspondences, &frame_points, &key_points);
  // pair.F maps frame points to lines in the key image: x_key^T F x_frame = 0.
  return ChanceOfFundamental(pair.F, frame_points, key_points, frame_size, key_size, comparisons_per_frame);
}

int ComparisonsPerFrame(int lookahead, int relocalization_candidates) {
  return (lookahead + 2) + (relocalization_candidates + 2);
}

}  // namespace vmap
