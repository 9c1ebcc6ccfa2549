#include "vmap/testing/memory_source.h"

#include <string>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace vmap::testing {

MemorySource::MemorySource(std::vector<cv::Mat> frames, std::vector<int> source_indices)
    : frames_(std::move(frames)), source_indices_(std::move(source_indices)) {
  info_.path = "memory";
  info_.format = SourceFormat::kImageFolder;
  info_.expected_frames = static_cast<long>(frames_.size());
  if (!frames_.empty()) info_.native_size = info_.frame_size = frames_.front().size();
}

std::optional<Frame> MemorySource::Next() {
  if (next_ >= frames_.size()) return std::nullopt;
  Frame frame;
  frame.index = static_cast<int>(next_);
  frame.source_index = next_ < source_indices_.size() ? source_indices_[next_] : static_cast<int>(next_);
  const cv::Mat& image = frames_[next_];
  if (image.channels() == 3) {
    frame.color = image;
    cv::cvtColor(image, frame.gray, cv::COLOR_BGR2GRAY);
  } else {
    frame.gray = image;
  }
  frame.source_name = "frame" + std::to_string(frame.source_index);
  ++next_;
  return frame;
}

}  // namespace vmap::testing
