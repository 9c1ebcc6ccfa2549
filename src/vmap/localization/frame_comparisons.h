#pragma once
// The comparisons of the frame being localized with key images: each made at most once a frame, and recorded in the
// order the frame asks for them, whether made before the frame reached the Localizer (`ahead`: LocalizeSequence's
// workers), meanwhile on helper threads (SpeculativeComparisons), or when asked. Every rule of the Localizer and the
// belief's evidence read this one record, so a sum over it is the same whichever thread made which comparison.

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/localization/key_comparison.h"
#include "vmap/localization/speculative_comparisons.h"

namespace vmap {

class FrameComparisons {
 public:
  // A comparison, and what the Localizer has done with it.
  struct Memo {
    KeyComparison comparison;
    bool weighed = false;         // its evidence is in the belief
    bool weighed_ranked = false;  // weighed given the frame's ranking (EvidenceModel::rank_alone)
    // Accepted by its heading mode against the frame's rivals (HeadingStandsOut), and weighed as such
    // (EvidenceModel::heading_stands_out).
    bool by_heading = false;
    bool weighed_by_heading = false;
  };
  // How the frame's features are compared with a key image (Localizer: KeyImageComparer::Compare with the frame's
  // iterations for that key image). With `helper_threads` above 0, Meanwhile makes comparisons on that many threads,
  // so `compare` must be thread-safe then.
  using CompareFn = SpeculativeComparisons::CompareFn;
  FrameComparisons(CompareFn compare, int helper_threads);
  ~FrameComparisons();
  FrameComparisons(const FrameComparisons&) = delete;
  FrameComparisons& operator=(const FrameComparisons&) = delete;

  // A new frame: nothing recorded; `ahead`, its comparisons made already, taken when asked for.
  void Begin(std::vector<KeyComparison> ahead);
  // The frame's comparison with key image `key`: recorded, or made (or taken from those made ahead or meanwhile) and
  // recorded now.
  KeyComparison Once(const ImageFeatures& features, int key);
  // The comparisons with `keys` that the frame is about to ask for, in that order: those not recorded or made ahead
  // are made meanwhile on the helper threads (none: nothing).
  void Meanwhile(const ImageFeatures& features, const std::vector<int>& keys);
  // A second comparison with a recorded key image replaces its memo, the first one's evidence already weighed.
  void Replace(KeyComparison second);
  // The frame is done: what the helpers have not started is dropped, the one in progress awaited (they read the
  // frame's features).
  void Finish();

  std::vector<Memo>::iterator begin() { return memos_.begin(); }
  std::vector<Memo>::iterator end() { return memos_.end(); }
  std::vector<Memo>::const_iterator begin() const { return memos_.begin(); }
  std::vector<Memo>::const_iterator end() const { return memos_.end(); }
  size_t size() const { return memos_.size(); }
  Memo& operator[](size_t i) { return memos_[i]; }
  const Memo& operator[](size_t i) const { return memos_[i]; }

 private:
  CompareFn compare_;
  std::vector<Memo> memos_;  // in the order Once was asked for them
  // Made before the frame got here, entering memos_ only when asked for: which ones there are depends on the
  // workers' timing.
  std::vector<KeyComparison> made_ahead_;
  std::unique_ptr<SpeculativeComparisons> speculation_;  // null without helper threads
};

}  // namespace vmap
