#pragma once
// A texture drawn from a seed, for worlds without photographs (tests, and `vmap simulate` without texture
// folders): random blobs, bars and speckle, plenty of corners for FAST and no repetitive pattern.

#include <opencv2/core.hpp>

namespace vmap {

cv::Mat RandomTexture(cv::Size size, cv::RNG& rng);  // 8-bit BGR

}  // namespace vmap
