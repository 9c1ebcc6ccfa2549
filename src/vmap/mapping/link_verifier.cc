#include "vmap/mapping/link_verifier.h"

#include <algorithm>

namespace vmap {

void LinkVerifier::Add(const KeyImage& from, const KeyImage& to, const Link& link, SimilarityMode similarity,
                       std::shared_ptr<const MagsacCheckpoint> checkpoint) {
  const auto pair = std::make_pair(from.frame_index, to.frame_index);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!results_.emplace(pair, PairComparison{}).second) return;
  }
  TentativeMatches matches;
  for (const Correspondence& c : link.correspondences) {
    matches.points0.push_back(c.p0);
    matches.points1.push_back(c.p1);
  }
  const int denominator = SimilarityDenominator(similarity, link.num_tentative, from.num_features, to.num_features);
  worker_.Post([this, pair, matches = std::move(matches), denominator, checkpoint = std::move(checkpoint)] {
    PairComparison verified = VerifyMatches(matches, denominator, verifier_, {}, nullptr, checkpoint);
    std::lock_guard<std::mutex> lock(mutex_);
    results_[pair] = std::move(verified);
  });
}

long LinkVerifier::Finish() {
  worker_.Wait();
  return static_cast<long>(results_.size());
}

int LinkVerifier::Apply(VisualMap* map, double tau) const {
  int kept = 0;
  for (Link& link : map->links) {
    const auto pair =
        std::make_pair(map->key_images[link.from_key].frame_index, map->key_images[link.to_key].frame_index);
    const PairComparison& verified = results_.at(pair);
    if (verified.Reaches(tau) == !link.below_tau) {
      link = MakeLink(verified, link.from_key, link.to_key, link.below_tau);
    } else {
      ++kept;
    }
  }
  return kept;
}

}  // namespace vmap
