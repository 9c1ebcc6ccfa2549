#include "vmap/localization/link_share_reference.h"

#include <algorithm>

#include "vmap/core/parallel_for.h"

namespace vmap {

std::vector<int> LinkShareReference(const std::vector<std::optional<SharedByKeys>>& link_after,
                                    const std::function<std::optional<SharedByKeys>(int p, int q)>& compare, double tau,
                                    int max_reach, int threads) {
  const int n = static_cast<int>(link_after.size());
  // Per position p: the verified matches with p + 2, p + 3, ... while S reaches tau. The walks are independent of
  // each other: the result does not depend on which thread made which.
  std::vector<std::vector<int>> walked(n);
  const auto walk = [&](int p) {
    if (p + 1 >= n || !link_after[p] || link_after[p]->similarity < tau) return;
    for (int q = p + 2; q < n && q <= p + max_reach && link_after[q - 1]; ++q) {
      const std::optional<SharedByKeys> shared = compare(p, q);
      if (!shared || shared->similarity < tau) break;
      walked[p].push_back(shared->num_verified);
    }
  };
  ParallelFor(n, threads, [&](size_t p) { walk(static_cast<int>(p)); });

  std::vector<int> forward(n, -1), backward(n, -1);
  for (int p = 0; p + 1 < n; ++p) {
    if (!link_after[p]) continue;
    // Positions go up, so the first walk to reach a position starts furthest back: its backward reference.
    if (backward[p + 1] < 0) backward[p + 1] = link_after[p]->num_verified;
    for (size_t i = 0; i < walked[p].size(); ++i) {
      if (backward[p + 2 + i] < 0) backward[p + 2 + i] = walked[p][i];
    }
    forward[p] = walked[p].empty() ? link_after[p]->num_verified : walked[p].back();
  }
  std::vector<int> references(n, 0);
  for (int p = 0; p < n; ++p) {
    if (forward[p] >= 0 && backward[p] >= 0) {
      references[p] = std::min(forward[p], backward[p]);
    } else {
      references[p] = std::max({forward[p], backward[p], 0});
    }
  }
  return references;
}

}  // namespace vmap
