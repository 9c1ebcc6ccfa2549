// A frame source over a video file, decoded by OpenCV's FFmpeg backend.

#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/internal.h"

namespace vmap::internal {
namespace {

// A damaged stretch of a video makes grab() fail for a few frames; this many failures in a row means
// the stream really ended (truncated file).
constexpr int kMaxConsecutiveFailures = 16;

class VideoSource : public FrameSource {
 public:
  VideoSource(const std::string& path, const FrameSourceOptions& options) : options_(options) {
    info_.path = path;
    info_.format = SourceFormat::kVideo;
    if (!capture_.open(path, cv::CAP_FFMPEG) || !capture_.isOpened()) {
      throw InputError("cannot open video '" + path +
                       "': it is not a video FFmpeg can decode, or it is truncated or corrupt; check the file "
                       "(ffprobe) or convert it to MP4");
    }
    info_.fps = capture_.get(cv::CAP_PROP_FPS);
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    frame_count_ = count > 0 ? static_cast<long>(std::llround(count)) : -1;
    if (frame_count_ > 0) {
      long end = options.last >= 0 ? std::min<long>(options.last + 1, frame_count_) : frame_count_;
      info_.expected_frames = end > options.first ? (end - options.first + options.stride - 1) / options.stride : 0;
    }
  }

  std::optional<Frame> Next() override {
    for (;;) {
      if (options_.last >= 0 && position_ > options_.last) return Finish();
      if (!GrabNext()) return Finish();
      const long index = position_++;
      if (index < options_.first || (index - options_.first) % options_.stride != 0) continue;
      Frame frame;
      if (!capture_.retrieve(frame.color) || frame.color.empty()) {
        ++skipped_;
        spdlog::warn("{}: frame {} could not be decoded; skipping it", info_.path, index);
        continue;
      }
      if (frame.color.channels() == 1) {
        frame.gray = frame.color;
        frame.color = cv::Mat();
      } else {
        cv::cvtColor(frame.color, frame.gray, cv::COLOR_BGR2GRAY);
      }
      frame.index = delivered_++;
      frame.source_index = static_cast<int>(index);
      frame.source_name = fmt::format("frame_{:06d}", index);
      const double msec = capture_.get(cv::CAP_PROP_POS_MSEC);
      frame.timestamp = msec >= 0 ? msec / 1000.0 : (info_.fps > 0 ? index / info_.fps : -1.0);
      if (frame.index == 0) {
        info_.native_size = frame.gray.size();
        info_.frame_size = TargetSize(info_.native_size, options_.resize);
      }
      FitFrame(frame, info_.frame_size, info_.native_size, options_, &size_warnings_);
      return frame;
    }
  }

  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return skipped_; }

 private:
  // Grabs the next frame, stepping over a damaged stretch; false at the end of the stream.
  bool GrabNext() {
    int failures = 0;
    while (!capture_.grab()) {
      // Past the announced end (or with no announced end) a failure is the end of the file.
      if (frame_count_ < 0 || position_ >= frame_count_ - 1 || ++failures >= kMaxConsecutiveFailures) return false;
      spdlog::warn("{}: frame {} could not be decoded; skipping it", info_.path, position_);
      ++skipped_;
      ++position_;
    }
    return true;
  }

  std::optional<Frame> Finish() {
    if (delivered_ == 0) {
      throw InputError("video '" + info_.path +
                       "' has no decodable frame in the requested range; it may be truncated or empty, or --first is "
                       "past its end");
    }
    if (!warned_short_ && frame_count_ > 0 && position_ < frame_count_ && options_.last < 0) {
      // The decoder drops a damaged frame silently; the shortfall against the container's count says so.
      warned_short_ = true;
      skipped_ += static_cast<int>(frame_count_ - position_);
      spdlog::warn("{}: the video announces {} frames but only {} could be decoded (damaged or truncated file)",
                   info_.path, frame_count_, position_);
    }
    return std::nullopt;
  }

  cv::VideoCapture capture_;
  FrameSourceOptions options_;
  SequenceInfo info_;
  long frame_count_ = -1;
  long position_ = 0;
  int delivered_ = 0;
  int skipped_ = 0;
  int size_warnings_ = 0;
  bool warned_short_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> OpenVideo(const std::string& path, const FrameSourceOptions& options) {
  return std::make_unique<VideoSource>(path, options);
}

}  // namespace vmap::internal
