// A V4L2 camera (/dev/video0) as a frame source, through OpenCV's V4L2 back end: FFmpeg would need libavdevice,
// which vmap does not otherwise depend on. A camera has no end: the run ends it (stop_requested), or the camera
// does (unplugged, or no frame for stream_timeout_seconds).

#include <chrono>
#include <filesystem>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/stopwatch.h"
#include "vmap/sources/internal.h"

namespace vmap::internal {
namespace {

class V4l2CameraSource : public FrameSource {
 public:
  V4l2CameraSource(const std::string& device, const FrameSourceOptions& options) : options_(options) {
    info_.path = device;
    info_.format = SourceFormat::kVideo;
    std::error_code ec;
    if (!std::filesystem::exists(device, ec)) {
      throw InputError("camera '" + device +
                       "' does not exist: there is no V4L2 device at that path. Connect the "
                       "camera and give the device it appears as (ls /dev/video*, or v4l2-ctl --list-devices)");
    }
    if (!capture_.open(device, cv::CAP_V4L2) || !capture_.isOpened()) {
      throw InputError("cannot open camera '" + device +
                       "' through V4L2: it is not a video capture device, another "
                       "program holds it, or this user may not read it (add the user to the 'video' group)");
    }
    info_.fps = capture_.get(cv::CAP_PROP_FPS);
    start_ = std::chrono::steady_clock::now();
  }

  std::optional<Frame> Next() override {
    cv::Mat color;
    for (;;) {
      if (options_.stop_requested && options_.stop_requested()) return std::nullopt;
      if (options_.last >= 0 && position_ > options_.last) return std::nullopt;
      const auto asked = std::chrono::steady_clock::now();
      if (!capture_.read(color) || color.empty()) {
        const double waited = SecondsSince(asked);
        if (waited >= options_.stream_timeout_seconds || ++failures_ > 16) {
          spdlog::warn("camera '{}' stopped delivering frames; ending the input", info_.path);
          return std::nullopt;
        }
        continue;
      }
      failures_ = 0;
      const long index = position_++;
      if (index < options_.first || (index - options_.first) % options_.stride != 0) continue;
      const std::string size_problem = FrameSizeProblem(color.size(), options_);
      if (!size_problem.empty()) {
        ++skipped_;
        spdlog::warn("{}: frame {} is {}x{}, {}; skipping it", info_.path, index, color.cols, color.rows, size_problem);
        continue;
      }
      Frame frame;
      if (color.channels() == 1) {
        frame.gray = color;
      } else {
        frame.color = color;
        cv::cvtColor(color, frame.gray, cv::COLOR_BGR2GRAY);
      }
      frame.index = delivered_++;
      frame.source_index = static_cast<int>(index);
      frame.source_name = fmt::format("frame_{:06d}", index);
      frame.timestamp = SecondsSince(start_);
      FitToSequence(frame, &info_, options_, &size_warnings_);
      return frame;
    }
  }

  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return skipped_; }

 private:
  FrameSourceOptions options_;
  SequenceInfo info_;
  cv::VideoCapture capture_;
  std::chrono::steady_clock::time_point start_;
  long position_ = 0;
  int delivered_ = 0;
  int skipped_ = 0;
  int failures_ = 0;
  int size_warnings_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> OpenV4l2Camera(const std::string& device, const FrameSourceOptions& options) {
  return std::make_unique<V4l2CameraSource>(device, options);
}

}  // namespace vmap::internal
