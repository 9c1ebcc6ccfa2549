#include "vmap/sources/image_frame.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/sources/internal.h"

namespace vmap {

Frame FrameFromImage(const cv::Mat& image, int index, const cv::Size& size, const std::string& what) {
  const int channels = image.channels();
  if (image.depth() != CV_8U || (channels != 1 && channels != 3 && channels != 4) || image.dims != 2) {
    throw InputError(what +
                     " must be an 8-bit image, grey (HxW) or BGR (HxWx3, as OpenCV reads it); convert it "
                     "to uint8 first");
  }
  const std::string problem = FrameSizeProblem(image.size());
  if (!problem.empty()) {
    throw InputError(what + " is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) + ", " + problem +
                     "; give an image of a usable size");
  }
  Frame frame;
  frame.native_size = image.size();
  frame.index = index;
  frame.source_index = index;
  frame.source_name = fmt::format("frame_{:06d}", index);  // as a video names its frames
  if (channels == 1) {
    frame.gray = image.clone();
  } else {
    frame.color = image.clone();
    if (channels == 4) cv::cvtColor(image, frame.color, cv::COLOR_BGRA2BGR);
    cv::cvtColor(frame.color, frame.gray, cv::COLOR_BGR2GRAY);
  }
  if (!size.empty()) {
    int warnings = 0;
    internal::FitFrame(frame, size, frame.gray.size(), FrameSourceOptions{}, &warnings);
  }
  return frame;
}

void FitFrameToSequence(Frame& frame, SequenceInfo* info, const FrameSourceOptions& options, int* warnings) {
  internal::FitToSequence(frame, info, options, warnings);
}

}  // namespace vmap
