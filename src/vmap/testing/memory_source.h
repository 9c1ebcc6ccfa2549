#pragma once
// Frames held in memory as a FrameSource: the tests' input to the build and the localizer, without files.

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/sources/frame_source.h"

namespace vmap::testing {

// Frames (BGR or grey) as a source; frame i has source index `source_indices[i]` (default: i) and source name
// "frame<source index>".
class MemorySource : public FrameSource {
 public:
  explicit MemorySource(std::vector<cv::Mat> frames, std::vector<int> source_indices = {});
  std::optional<Frame> Next() override;
  const SequenceInfo& info() const override { return info_; }

 private:
  std::vector<cv::Mat> frames_;
  std::vector<int> source_indices_;
  size_t next_ = 0;
  SequenceInfo info_;
};

}  // namespace vmap::testing
