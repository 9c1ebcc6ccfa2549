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

bool PassesChance(const KeyComparison& comparison, double max_log10_nfa) {
  return comparison.accepted && comparison.log10_nfa <= max_log10_nfa;
}

}  // namespace vmap
