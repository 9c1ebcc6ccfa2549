#pragma once
// The node's debug image: the camera frame beside the key image it is steered to, the verified matches drawn
// between them as in the map's match figures (report/match_figure.h), with the localization in the caption.

#include <string>

#include <opencv2/core.hpp>

#include "vmap/localization/localizer.h"

namespace vmap::ros_node {

// The comparison a robot steers by: against next_key, or against key at the route's end or when next_key did
// not match. Null when neither was compared.
const KeyComparison* SteeringComparison(const LocalizationResult& result);

// `frame` (grey or BGR) beside `key_image` (the key image of `comparison`, grey or BGR; empty: a grey box) with
// the comparison's verified matches, captioned with `caption` and the comparison's S and counts. At most
// `max_width` pixels wide. Returns an 8-bit BGR image.
cv::Mat DrawDebugImage(const cv::Mat& frame, const cv::Mat& key_image, const KeyComparison* comparison,
                       const std::string& caption, int max_width = 1280);

}  // namespace vmap::ros_node
