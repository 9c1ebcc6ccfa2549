#include "vmap/mapping/pair_match.h"

#include <chrono>

#include "vmap/core/stopwatch.h"

namespace vmap {

PairMatch MatchPair(const Matcher& matcher, const PairImage& image0, const PairImage& image1,
                    const VerifierOptions& verifier, const HeadingOptions& heading, const Camera* camera) {
  PairMatch pair;
  auto start = std::chrono::steady_clock::now();
  const auto features0 = matcher.ExtractFrame(image0.gray, image0.bgr);
  const auto features1 = matcher.ExtractFrame(image1.gray, image1.bgr);
  pair.extract_seconds = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  pair.matches = matcher.Match(*features0, *features1);
  pair.match_seconds = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  if (static_cast<int>(pair.matches.size()) >= verifier.min_matches) {
    // The estimator of a map's links (DecisionVerifier): with OpenCV's USAC_MAGSAC instead, a third of kitti07's links
    // at tau 0.6 verified a few matches fewer, some below the tau their link had passed.
    VerifierOptions as_links = verifier;
    as_links.own_magsac = verifier.method == VerifierMethod::kMagsac;
    pair.fundamental = EstimateFundamental(pair.matches.points0, pair.matches.points1, as_links);
  }
  pair.verify_seconds = SecondsSince(start);
  // The mode of all tentative matches unless F keeps many: across seasons F rarely holds (geometry/heading.h).
  start = std::chrono::steady_clock::now();
  pair.heading =
      EstimateHeading(pair.matches.points0, pair.matches.points1, pair.fundamental.inlier_mask, heading, camera);
  pair.heading_seconds = SecondsSince(start);
  pair.similarity = pair.matches.size() == 0 ? 0.0 : double(pair.fundamental.num_inliers) / double(pair.matches.size());
  return pair;
}

}  // namespace vmap
