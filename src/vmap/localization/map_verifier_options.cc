#include "vmap/localization/map_verifier_options.h"

#include <algorithm>

namespace vmap {

VerifierOptions MapVerifierOptions(const VerifierOptions& recorded, int max_iterations, int loop_points) {
  // ORB's matches (no scores) keep the map's verifier with the cap localization always had.
  constexpr int kUnscoredMaxIterations = 5000;
  VerifierOptions options = recorded;
  options.max_iterations = std::min(options.max_iterations, kUnscoredMaxIterations);
  // Scored matches: at most `max_iterations` samples on the `loop_points` best-scored ones.
  options.loop_points = loop_points;
  options.max_samples_to_reject = std::min(options.max_iterations, max_iterations);
  options.Check();
  return options;
}

}  // namespace vmap
