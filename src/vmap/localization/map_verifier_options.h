#pragma once

#include "vmap/geometry/fundamental.h"

namespace vmap {

// The verifier the map records (options.verifier in map.json), bounded: a comparison asks "is the frame at this key
// image?", not for the best F, so its cost must not grow with the matches or fall to MAGSAC's iteration cap.
// - Scored matches (XFeat, ALIKED) of a map verified by MAGSAC: vmap's MAGSAC++ (within a seed change of
//   OpenCV's) with at most `max_iterations` samples drawn from the `loop_points` best-scored matches, its model
//   refined on all of them (VerifierOptions::loop_points): thousands of XFeat matches cost what 512 do.
// - Matches without scores (ORB): the map's verifier with at most 5000 iterations. Why capped: a frame compared
//   with a key image it barely overlaps has a low inlier ratio, for which MAGSAC runs to the map's 100,000
//   iterations (about a second); such a pair fails the acceptance test anyway.
// Measured with bench/verify_bench (docs/matchers.md, "Speed of verification").
VerifierOptions MapVerifierOptions(const VerifierOptions& recorded, int max_iterations = 1000, int loop_points = 512);

}  // namespace vmap
