#pragma once
// Comparisons of a frame made ahead on helper threads while the Localizer decides
// (LocalizerOptions::comparison_threads).
//
// Across seasons nearly all of a frame's time is verification (OpenCV's MAGSAC on the matches, ~10 ms on ORB's
// corridor_conditions frames), and the Localizer compares one key image after another, each only once the one before
// has been weighed. Where the next comparisons are known before the one in hand is done (the key images after the
// tracked one, the ranking's other candidates, the belief's window) they are made on a second core meanwhile. A
// comparison depends only on the frame and the key image, so Take hands back what the Localizer would compute itself:
// the results, and the order in which the Localizer records them (CompareOnce), are those of comparing in sequence.

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/localization/key_comparison.h"

namespace vmap {

class SpeculativeComparisons {
 public:
  using CompareFn = std::function<KeyComparison(const ImageFeatures& features, int key)>;
  // `compare` must be safe to call on other threads while the owner runs (Localizer::Compare is). `helpers`
  // threads (at least 1) make the comparisons, started with the first Add and joined by the destructor.
  SpeculativeComparisons(CompareFn compare, int helpers);
  ~SpeculativeComparisons();
  SpeculativeComparisons(const SpeculativeComparisons&) = delete;
  SpeculativeComparisons& operator=(const SpeculativeComparisons&) = delete;

  // Queues the frame's comparisons with `keys`, in this order, skipping those queued already. Every call until
  // Finish must give the same frame; `features` must live until Finish.
  void Add(const ImageFeatures& features, const std::vector<int>& keys);
  // The comparison with `key` when it was queued: waits for it when the helper is making it; none when it was not
  // queued, or not yet started (it is dropped then: the caller makes it itself, at once).
  std::optional<KeyComparison> Take(int key);
  // The frame is done: drops what was not started and waits for the comparison in progress, if any.
  void Finish();

 private:
  struct Slot {
    int key = -1;
    enum class State { kQueued, kRunning, kDone, kDropped } state = State::kQueued;
    KeyComparison comparison;
    std::exception_ptr error;
  };
  void Run();

  CompareFn compare_;
  int helpers_ = 1;
  std::mutex mutex_;
  std::condition_variable changed_;
  const ImageFeatures* features_ = nullptr;  // the frame's, while slots_ are queued
  std::deque<Slot> slots_;                   // the frame's; a deque keeps references to them valid
  bool stop_ = false;
  std::vector<std::thread> threads_;  // started with the first Add
};

}  // namespace vmap
