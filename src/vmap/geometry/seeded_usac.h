#pragma once
// OpenCV's USAC as vmap runs it, for the fundamental (fundamental.cc), homography (homography.cc) and essential
// (relative_pose.cc) matrices: seeded, so that the same input gives the same model, on one thread, with uniform
// sampling and the grid neighbourhood (the presets of OpenCV 4.6's flag-based call, usac::setParameters). The score
// and the local optimisation are the caller's.

#include <opencv2/calib3d.hpp>

namespace vmap {

// USAC's parameters with `confidence`, `max_iterations`, the inlier `threshold` (in the caller's units) and the
// random generator's state `seed`.
cv::UsacParams SeededUsacParams(double confidence, int max_iterations, double threshold, int seed);

}  // namespace vmap
