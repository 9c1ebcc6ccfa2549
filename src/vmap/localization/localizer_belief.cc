// The Localizer's belief over the route (route_belief.h): every comparison of a frame weighs it, and a frame whose
// tracked position the belief does not single out is uncertain.
#include "vmap/localization/localizer.h"

namespace vmap {

namespace {

// "Near" the chosen key image: within two route positions, the tolerance of the goal "no frame confidently at a
// key image more than 2 places away" (key images two apart often both see the frame).
constexpr int kNear = 2;

}  // namespace

void Localizer::WeighComparisons() {
  for (Memo& m : comparisons_) {
    if (!m.used || m.weighed) continue;
    m.weighed = true;
    const int key = m.comparison.key;
    const int position = route_position_of_key_[key];
    if (position >= 0) belief_.Weigh(position, EvidenceLogRatio(evidence_, m.comparison, link_verified_[key]));
  }
  belief_.Normalize();
}

void Localizer::Believe(LocalizationResult& result) {
  WeighComparisons();
  if (result.route_position < 0) return;
  result.confidence = belief_.MassWithin(result.route_position, kNear);
  const bool placed =
      result.status == LocalizationStatus::kTracking || result.status == LocalizationStatus::kRelocalized;
  if (placed && result.confidence < options_.belief.min_confidence) result.status = LocalizationStatus::kUncertain;
}

}  // namespace vmap
