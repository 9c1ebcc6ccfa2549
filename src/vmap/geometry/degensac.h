#pragma once
// DEGENSAC's plane-and-parallax recovery of a fundamental matrix from a sample that is mostly on one plane
// (Chum, Werner & Matas, CVPR 2005), for vmap's MAGSAC++ (magsac.cc). Internal to geometry/.

#include "vmap/geometry/fundamental_solvers.h"
#include "vmap/geometry/magsac_scoring.h"
#include "vmap/geometry/robust_loop.h"

namespace vmap::internal {

// DEGENSAC (Chum, Werner & Matas 2005): when five of the seven sample points fit one homography H, the 7-point
// model may explain the plane only. Then F is re-estimated as [e']_x H with the epipole from two off-plane
// points (plane and parallax), by a small RANSAC. Returns whether the sample was degenerate; the recovered
// model and its score (without SPRT) are the best of that search.
bool RecoverIfDegenerate(const NormalizedPoints& points, const SevenPointSample& sample, const Model& model,
                         MagsacScorer& scorer, RandomStream& random, Model* recovered, Score* recovered_score);

}  // namespace vmap::internal
