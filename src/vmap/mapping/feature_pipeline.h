#pragma once
// MapBuilder's workers: frames' features extracted, and the frames compared with the key images, a few frames
// ahead of Algorithm 1 (internal to mapping/).

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "vmap/core/ordered_pipeline.h"
#include "vmap/features/matcher.h"
#include "vmap/mapping/key_image_selector.h"

namespace vmap {

// Compares a key image with a frame for the selectors whose thresholds are `taus`; `abandon` may stop it.
using CompareForTausFn =
    std::function<PairComparison(const FrameRecord& key, const FrameRecord& frame, const std::vector<double>& taus,
                                 const std::function<bool()>& abandon)>;

// Adds `tau` to the ascending `taus` unless it is there.
void AddThreshold(double tau, std::vector<double>* taus);

// The thresholds the comparison of frame `frame_index` with key image `key_index` settles, fixed by the maps
// alone (never by the threads' timing: where an estimation that stops early stops, and so its S, depends on
// every threshold it settles). The previous frame may become any selector's key image during this frame, so its
// comparison settles every threshold; an older key image is compared for the selectors holding it when the
// frame comes (`holders`, ascending), and for `tau` (a selector that moves to it during the frame, after frames
// that repeated the key image's view). Without holders: every threshold.
std::vector<double> ThresholdsToSettle(int key_index, int frame_index, const std::vector<double>* holders,
                                       const std::vector<double>& all_taus, double tau);

// A key image the workers compare frames with, and the thresholds (ascending) of the selectors that hold it.
struct CurrentKey {
  FrameRecord record;
  std::vector<double> taus;
};

// A frame with its features and the comparisons the workers already made for it (by key frame index).
struct PipelineItem {
  FrameRecord record;
  std::map<int, PairComparison> comparisons;
};

// Takes frames from the consumer (TryPush) and, on `workers` threads, extracts their features and compares
// them with the current key images, a few frames ahead of the consumer, which receives them in order (Next):
// an OrderedPipeline whose work follows the key images. The frames in flight are bounded by `depth`; the
// frames come decoded (BuildMap reads them ahead on a thread of their own, ReadAheadSource).
//
// Why compare ahead: a frame is compared with the same key image as the frames before it until S drops,
// so those comparisons do not depend on each other and can run in parallel.
//
// Key changes are followed by the workers too. When a worker sees frame j fall below tau against a key
// image, every selector holding that key with tau or a higher threshold leaves it at frame j at the latest,
// for frame j-1 (or for j itself when j-1 is that key: a link below tau); the others keep it. Frame j and the
// later ones are compared with that successor at once for those thresholds, as the consumer will ask, instead
// of with the old key at low S, where the estimator works longest only for the result to be thrown away, and
// the consumer then redoing the comparisons one by one while the workers wait. A comparison whose every
// threshold left its key at an earlier frame meanwhile is abandoned.
//
// The consumer compares whatever the workers did not guess (also when the selector picks another successor,
// as it does for a frame that repeats the key image's view). ComparePair is deterministic, so the map is the
// same whatever the threads do.
class FeaturePipeline {
 public:
  // `all_taus`: every selector's threshold, ascending.
  FeaturePipeline(const Matcher& matcher, int depth, int workers, CompareForTausFn compare,
                  std::vector<double> all_taus);
  ~FeaturePipeline();

  // Hands `frame` to the workers, unless `depth` frames are in the pipeline already: then false, and `frame`
  // is left as it was (take an item out with Next() first). Rethrows a worker's error.
  bool TryPush(Frame& frame);

  // No more frames: Next() returns nullopt once every frame pushed has come out.
  void Close();

  // The key images (distinct) that frames extracted from now on are compared with, each with the thresholds
  // of the selectors holding it: a frame below the lowest makes all of them leave the key.
  void SetCurrentKeys(std::vector<CurrentKey> keys);

  // The next frame in order, waiting for it; nullopt at the end (after Close). Rethrows a worker's error.
  std::optional<PipelineItem> Next();

  // The next frame when it is ready now, otherwise nullopt.
  std::optional<PipelineItem> TryNext();

  long extracted() const { return extracted_; }

 private:
  std::optional<PipelineItem> Took(std::optional<PipelineItem> item);
  PipelineItem ExtractAndCompare(Frame decoded);
  // The key image a selector with threshold `tau` that held `key_index` compares `frame_index` with, as far as
  // the workers know: that key, or the successor of a key that this frame or an earlier one fell below tau
  // against, and so on. Call with mutex_ held.
  int ResolveKey(int key_index, double tau, int frame_index) const;
  // Frame `frame_index` fell below `tau` against the key image `key_index`: the selectors holding it with tau
  // or a higher threshold leave it here at the latest, for the successor Algorithm 1 gives.
  void Retire(int key_index, int frame_index, double tau);

  const Matcher& matcher_;
  const CompareForTausFn compare_;
  const std::vector<double> all_taus_;
  const int depth_;
  std::atomic<long> extracted_{0};
  // What the workers share to follow key changes.
  std::mutex mutex_;
  std::shared_ptr<const std::vector<CurrentKey>> current_keys_;
  struct Retirement {
    int at_frame;     // a frame seen to fall below from_tau against the key
    double from_tau;  // the lowest threshold it fell below: selectors with this tau or a higher one leave
    int successor;    // the frame that replaces the key for them
  };
  std::map<int, std::vector<Retirement>> retired_;  // by key frame index
  std::map<int, FrameRecord> recent_;               // extracted frames a successor may be taken from, by frame index
  OrderedPipeline<Frame, PipelineItem> frames_;     // last: its workers start once everything they use exists
};

}  // namespace vmap
