#include "vmap/localization/speculative_comparisons.h"

#include <algorithm>
#include <utility>

namespace vmap {

SpeculativeComparisons::SpeculativeComparisons(CompareFn compare, int helpers)
    : compare_(std::move(compare)), helpers_(std::max(1, helpers)) {}

SpeculativeComparisons::~SpeculativeComparisons() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  for (std::thread& thread : threads_) thread.join();
}

void SpeculativeComparisons::Add(const ImageFeatures& features, const std::vector<int>& keys) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    features_ = &features;
    for (int key : keys) {
      if (std::none_of(slots_.begin(), slots_.end(), [&](const Slot& s) { return s.key == key; })) {
        slots_.emplace_back();
        slots_.back().key = key;
      }
    }
    while (static_cast<int>(threads_.size()) < helpers_) threads_.emplace_back([this] { Run(); });
  }
  changed_.notify_all();
}

std::optional<KeyComparison> SpeculativeComparisons::Take(int key) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto found = std::find_if(slots_.begin(), slots_.end(), [&](const Slot& s) { return s.key == key; });
  if (found == slots_.end()) return std::nullopt;
  Slot* slot = &*found;  // Add may grow slots_ while this waits
  if (slot->state == Slot::State::kQueued) slot->state = Slot::State::kDropped;
  if (slot->state == Slot::State::kDropped) return std::nullopt;
  changed_.wait(lock, [&] { return slot->state == Slot::State::kDone; });
  if (slot->error) std::rethrow_exception(slot->error);
  return slot->comparison;
}

void SpeculativeComparisons::Finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (Slot& s : slots_) {
    if (s.state == Slot::State::kQueued) s.state = Slot::State::kDropped;
  }
  changed_.wait(lock, [&] {
    return std::none_of(slots_.begin(), slots_.end(), [](const Slot& s) { return s.state == Slot::State::kRunning; });
  });
  slots_.clear();
  features_ = nullptr;
}

void SpeculativeComparisons::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    auto queued = slots_.end();
    changed_.wait(lock, [&] {
      queued =
          std::find_if(slots_.begin(), slots_.end(), [](const Slot& s) { return s.state == Slot::State::kQueued; });
      return stop_ || queued != slots_.end();
    });
    if (stop_) return;
    Slot& slot = *queued;
    slot.state = Slot::State::kRunning;
    const ImageFeatures& features = *features_;
    lock.unlock();
    KeyComparison comparison;
    std::exception_ptr error;
    try {
      comparison = compare_(features, slot.key);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    slot.comparison = std::move(comparison);
    slot.error = error;
    slot.state = Slot::State::kDone;
    changed_.notify_all();
  }
}

}  // namespace vmap
