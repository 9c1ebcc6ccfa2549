#pragma once
// Links verified in full after decisions that stopped early (internal to mapping/).

#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "vmap/core/serial_worker.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/key_image_selector.h"

namespace vmap {

// Verifies links in full, on a thread of its own while the build goes on, when the decisions stopped early:
// the tables are then computed from exact link values. The estimation goes on from where the deciding
// comparison stopped, on the link's own tentative matches (no matching, no features kept). A link shared by
// several taus (same two frames) is verified once.
class LinkVerifier {
 public:
  explicit LinkVerifier(const VerifierOptions& verifier) : verifier_(verifier) {}

  // Queues `link`, between key images `from` and `to`, unless that pair of frames is queued already.
  // `checkpoint`, where the comparison that made the link stopped, saves the samples it drew already.
  void Add(const KeyImage& from, const KeyImage& to, const Link& link, SimilarityMode similarity,
           std::shared_ptr<const MagsacCheckpoint> checkpoint);

  // Waits for every link queued so far (a snapshot applies them); rethrows a failure.
  void Wait() { worker_.Wait(); }

  // Waits for every verification; rethrows a failure. Returns how many links were verified.
  long Finish();

  // Replaces the links of `map`, built with threshold `tau`, by their verifications (after Finish). A verification
  // that contradicts the decision (a link at S >= tau found below tau, or the reverse for a link below tau: the
  // two estimates differ by the noise of a seed change) leaves the deciding comparison in place, so that every
  // link keeps the meaning Algorithm 1 gives it.
  // Returns how many links kept their deciding comparison.
  int Apply(VisualMap* map, double tau) const;

 private:
  const VerifierOptions verifier_;
  std::mutex mutex_;
  std::map<std::pair<int, int>, PairComparison> results_;  // by (from, to) frame index
  SerialWorker worker_;                                    // last: destroyed first, so its jobs never outlive results_
};

}  // namespace vmap
