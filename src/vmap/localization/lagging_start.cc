#include "vmap/localization/lagging_start.h"

#include <algorithm>

namespace vmap {

bool LaggingStart::Lags() const {
  if (frames_ <= 0 || frames_since_start_ > start_frames_ || static_cast<int>(recent_positions_.size()) < frames_) {
    return false;
  }
  const int moved = recent_positions_.back() - recent_positions_.front();
  return moved >= 0 && moved < 2;
}

void LaggingStart::Remember(int position) {
  if (frames_since_start_ <= start_frames_) ++frames_since_start_;
  if (position < 0) {
    recent_positions_.clear();
    return;
  }
  recent_positions_.push_back(position);
  while (static_cast<int>(recent_positions_.size()) > std::max(1, frames_)) recent_positions_.pop_front();
}

void LaggingStart::Reset() {
  frames_since_start_ = 0;
  recent_positions_.clear();
}

}  // namespace vmap
