#include "vmap/localization/still_frame.h"

#include <cstddef>

#include <opencv2/core.hpp>

namespace vmap {

bool StandsStill(const Matcher& matcher, const ImageFeatures& before, const ImageFeatures& frame, double share) {
  // Half a pixel: a camera's noise moves a still frame's matches less (michigan_seasons with noise: >= 97 % of them),
  // while a robot moving at the corridor's pace moves its median match 1.9 px a frame.
  constexpr double kStillPx = 0.5;
  if (share <= 0.0) return false;
  const TentativeMatches matches = matcher.Match(before, frame);
  if (matches.size() == 0) return false;
  size_t still = 0;
  for (size_t i = 0; i < matches.size(); ++i) still += cv::norm(matches.points1[i] - matches.points0[i]) < kStillPx;
  return still >= share * matches.size();
}

}  // namespace vmap
