#pragma once
// A frame from an image held in memory rather than read from an input: a robot's camera callback, the Python
// module's numpy images.

#include <string>

#include <opencv2/core.hpp>

#include "vmap/sources/frame_source.h"

namespace vmap {

// The frame of `image`, 8-bit grey, BGR or BGRA (grey by cv::cvtColor), numbered `index`, brought to `size`
// when it is not empty as the sources bring frames to --resize. Throws InputError naming `what` when the image
// is of another type or of a size FrameSizeProblem refuses.
Frame FrameFromImage(const cv::Mat& image, int index, const cv::Size& size = {}, const std::string& what = "image");

// Brings a frame that a host decoded itself (a ROS node's camera topic) into its sequence as the sources bring
// theirs: the first frame (index 0) sets `info`'s native size and the size frames are delivered at
// (options.resize); every frame is then brought to that size (one of another size than the first: a warning, or an
// OptionError with options.strict).
void FitFrameToSequence(Frame& frame, SequenceInfo* info, const FrameSourceOptions& options, int* warnings);

}  // namespace vmap
