#include "vmap/geometry/seeded_usac.h"

namespace vmap {

cv::UsacParams SeededUsacParams(double confidence, int max_iterations, double threshold, int seed) {
  cv::UsacParams params;
  params.confidence = confidence;
  params.maxIterations = max_iterations;
  params.threshold = threshold;
  params.randomGeneratorState = seed;
  params.isParallel = false;
  params.sampler = cv::SAMPLING_UNIFORM;
  params.neighborsSearch = cv::NEIGH_GRID;
  return params;
}

}  // namespace vmap
