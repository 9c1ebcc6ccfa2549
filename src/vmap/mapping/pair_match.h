#pragma once
// One image pair through a matcher and the verifier, in full: what `vmap match` and the Python module's
// vmap.match show to try a matcher on one's own images.

#include <utility>

#include <opencv2/core.hpp>

#include "vmap/features/matcher.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/heading.h"

namespace vmap {

struct PairMatch {
  TentativeMatches matches;       // in the matcher's order
  FundamentalResult fundamental;  // its inlier_mask is one per match; !success below min_matches
  double similarity = 0.0;        // S = verified / tentative (0 without matches)
  HeadingEstimate heading;        // x in image 1 minus x in image 0 at the scene both show (geometry/heading.h)
  // Wall time of each step, seconds: both images' extraction, matching, verification.
  double extract_seconds = 0.0;
  double match_seconds = 0.0;
  double verify_seconds = 0.0;
  double heading_seconds = 0.0;
};

// One image of a pair: 8-bit grey, and the same image as 8-bit BGR when it has colour (else empty), for a
// matcher that reads colour (Matcher::reads_color). Built from a grey cv::Mat alone where there is no colour.
struct PairImage {
  PairImage(cv::Mat gray_image, cv::Mat bgr_image = {}) : gray(std::move(gray_image)), bgr(std::move(bgr_image)) {}
  cv::Mat gray;
  cv::Mat bgr;
};

// Extracts both images' features (Matcher::ExtractFrame), matches them, and verifies the matches
// exhaustively with `verifier` when there are at least verifier.min_matches of them, and estimates the heading
// (with `camera`, of images of its size, also in degrees).
PairMatch MatchPair(const Matcher& matcher, const PairImage& image0, const PairImage& image1,
                    const VerifierOptions& verifier, const HeadingOptions& heading = {},
                    const Camera* camera = nullptr);

}  // namespace vmap
