// The Localizer's belief over the route (route_belief.h): every comparison of a frame weighs it; a frame whose
// tracked position the belief does not single out is questioned (compared around the belief's peak, and over the
// whole route when the belief is flat), moved to where the belief puts it, or else uncertain.
#include <algorithm>

#include "vmap/localization/localizer.h"

namespace vmap {

namespace {

// "Near" the chosen key image: within two route positions, the tolerance of the goal "no frame confidently at a
// key image more than 2 places away" (key images two apart often both see the frame).
constexpr int kNear = 2;

}  // namespace

void Localizer::WeighComparisons() {
  bool weighed = false;
  for (Memo& m : comparisons_) {
    if (!m.used || m.weighed) continue;
    m.weighed = weighed = true;
    const int key = m.comparison.key;
    const int position = route_position_of_key_[key];
    if (position >= 0) belief_.Weigh(position, EvidenceLogRatio(evidence_, m.comparison, link_verified_[key]));
  }
  if (weighed) belief_.Normalize();
}

bool Localizer::SinglesOut(int position) const {
  // Near the position: at least min_confidence of the belief, and twice what a flat belief holds there (on a
  // short route a flat belief holds much of its mass within two places of anywhere).
  const double near = belief_.MassWithin(position, kNear);
  const int positions = static_cast<int>(belief_.probabilities().size());
  const double flat = static_cast<double>(std::min(positions, 2 * kNear + 1)) / positions;
  return near >= options_.belief.min_confidence && near >= 2.0 * flat;
}

void Localizer::Believe(LocalizationResult& result, const Frame& frame, const ImageFeatures& features) {
  WeighComparisons();
  Question(result, frame, features);
  if (result.route_position < 0) return;
  result.confidence = belief_.MassWithin(result.route_position, kNear);
  const bool placed =
      result.status == LocalizationStatus::kTracking || result.status == LocalizationStatus::kRelocalized;
  if (placed && result.confidence < options_.belief.min_confidence) result.status = LocalizationStatus::kUncertain;
}

void Localizer::Question(LocalizationResult& result, const Frame& frame, const ImageFeatures& features) {
  const int window = options_.belief.window;
  const double min_confidence = options_.belief.min_confidence;
  const int last = static_cast<int>(route_.size()) - 1;
  auto doubted = [&] {
    return result.status == LocalizationStatus::kLost || result.route_position < 0 ||
           belief_.MassWithin(result.route_position, kNear) < min_confidence;
  };
  if (window <= 0 || min_confidence <= 0.0 || !doubted()) return;
  // The key image stops explaining the frame: look where the belief has it, behind and ahead of its peak (the key
  // images whose evidence weighs the positions within `window` of it).
  auto compare_around = [&](int centre) {
    for (int q = std::max(0, centre - window); q <= std::min(last, centre + window + 1); ++q) {
      CompareOnce(features, route_[q]);
    }
    WeighComparisons();
  };
  compare_around(belief_.Peak());
  if (!belief_confident_) {
    // Flat: nothing singled out. The best-ranked key images of the whole route weigh it (a relocalization). A
    // flat belief does not move the estimate on one frame's evidence: the frames after it confirm a place.
    CompareBestRanked(frame, features);
    WeighComparisons();
    return;
  }
  const int peak = belief_.Peak();
  if (!doubted() || !SinglesOut(peak)) return;
  // A frame relocalized elsewhere on a verified key image (the robot may have been carried) keeps that place as
  // its best guess and is uncertain until the frames after it confirm or refute it; a tracked frame held at a key
  // image the belief does not support, or a lost one, moves to the belief's peak.
  if (result.status == LocalizationStatus::kRelocalized) return;
  // The run of frames before this one singled out a place, and this frame's evidence leaves it there: the
  // estimate moves there. It is relocalized when a key image there verifies; on weak evidence alone (nothing
  // verifies) its key images are the best guess, not to steer by.
  LocalizationResult moved;
  moved.candidates = std::move(result.candidates);
  Describe(moved, peak, features);
  const bool verified = moved.to_key.accepted || moved.to_next.accepted;
  moved.status = verified ? LocalizationStatus::kRelocalized : LocalizationStatus::kUncertain;
  position_ = peak;
  step_back_ruled_out_ = {};
  if (verified) lost_in_a_row_ = 0;
  result = std::move(moved);
}

}  // namespace vmap
