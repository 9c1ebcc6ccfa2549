#include "vmap/localization/frame_comparisons.h"

#include <algorithm>
#include <optional>
#include <utility>

namespace vmap {

FrameComparisons::FrameComparisons(CompareFn compare, int helper_threads) : compare_(std::move(compare)) {
  if (helper_threads > 0) speculation_ = std::make_unique<SpeculativeComparisons>(compare_, helper_threads);
}

FrameComparisons::~FrameComparisons() = default;

void FrameComparisons::Begin(std::vector<KeyComparison> ahead) {
  memos_.clear();
  made_ahead_ = std::move(ahead);
}

KeyComparison FrameComparisons::Once(const ImageFeatures& features, int key) {
  for (const Memo& m : memos_) {
    if (m.comparison.key == key) return m.comparison;
  }
  // Recorded only when asked for, so the memo holds what the frame asked for in the order it asked, and every sum over
  // it is as when each comparison is made in turn.
  std::optional<KeyComparison> made;
  const auto ahead =
      std::find_if(made_ahead_.begin(), made_ahead_.end(), [&](const KeyComparison& c) { return c.key == key; });
  if (ahead != made_ahead_.end()) {
    made = std::move(*ahead);
  } else if (speculation_) {
    made = speculation_->Take(key);
  }
  memos_.push_back({made ? std::move(*made) : compare_(features, key)});
  return memos_.back().comparison;
}

void FrameComparisons::Meanwhile(const ImageFeatures& features, const std::vector<int>& keys) {
  if (!speculation_) return;
  std::vector<int> missing;
  for (const int key : keys) {
    const auto has_key = [&](const KeyComparison& c) { return c.key == key; };
    if (std::none_of(memos_.begin(), memos_.end(), [&](const Memo& m) { return has_key(m.comparison); }) &&
        std::none_of(made_ahead_.begin(), made_ahead_.end(), has_key))
      missing.push_back(key);
  }
  if (!missing.empty()) speculation_->Add(features, missing);
}

void FrameComparisons::Replace(KeyComparison second) {
  for (Memo& m : memos_) {
    if (m.comparison.key == second.key) {
      m = {std::move(second), /*weighed=*/true};
      return;
    }
  }
}

void FrameComparisons::Finish() {
  if (speculation_) speculation_->Finish();
}

}  // namespace vmap
