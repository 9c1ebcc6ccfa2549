#include "vmap/localization/key_comparison.h"

namespace vmap {

bool IsBetterMatch(const KeyComparison& a, const KeyComparison& b) {
  if (!a.accepted) return false;
  if (!b.accepted) return true;
  if (a.num_verified != b.num_verified) return a.num_verified > b.num_verified;
  return a.similarity > b.similarity;
}

bool FitsBetter(const KeyComparison& a, const KeyComparison& b) {
  if (a.accepted || b.accepted) return IsBetterMatch(a, b);
  if (a.num_verified != b.num_verified) return a.num_verified > b.num_verified;
  return a.similarity > b.similarity;
}

}  // namespace vmap
