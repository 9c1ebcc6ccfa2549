#pragma once
// Verified matches of a scene seen larger or smaller in the frame than in its key image: what the controller's goal
// check and the tracker's along-route measurement read a key image's apparent scale from.

#include <vector>

#include <opencv2/core.hpp>

#include "vmap/map/visual_map.h"

namespace vmap::testing {

// 60 matches spread over a 640x480 key image, each frame point `scale` times as far from the image centre as its
// key image point ({frame, key} pairs, as a comparison records them).
inline std::vector<Correspondence> ZoomedMatches(double scale) {
  std::vector<Correspondence> matches;
  for (int i = 0; i < 60; ++i) {
    const cv::Point2f key(40.f + 9.f * i, 60.f + static_cast<float>((i * 37) % 360));
    const cv::Point2f frame = cv::Point2f(320, 240) + static_cast<float>(scale) * (key - cv::Point2f(320, 240));
    matches.push_back({frame, key});
  }
  return matches;
}

}  // namespace vmap::testing
