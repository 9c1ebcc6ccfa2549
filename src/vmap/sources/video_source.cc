// A frame source over a video file, decoded with FFmpeg's libavformat/libavcodec.
//
// Why not cv::VideoCapture: OpenCV 4.6 always decodes with one thread per core, and vmap already keeps
// every core busy with feature extraction and verification. Decoding on one thread costs less CPU per frame
// (docs/measurements/code-choices.md, "Decoding video on one thread"), and frames skipped by
// --first/--stride are never converted to BGR. The BGR conversion is the one OpenCV makes (swscale, bicubic), so the
// frames are pixel-identical to cv::VideoCapture's.

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/display.h>
#include <libavutil/log.h>
#include <libswscale/swscale.h>
}

#include <chrono>
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/internal.h"

namespace vmap::internal {
namespace {

// A damaged stretch of a video makes this many packets in a row fail to decode: the stream really ended.
constexpr int kMaxConsecutiveFailures = 16;

struct FormatCloser {
  void operator()(AVFormatContext* context) const { avformat_close_input(&context); }
};
struct CodecFreer {
  void operator()(AVCodecContext* context) const { avcodec_free_context(&context); }
};
struct PacketFreer {
  void operator()(AVPacket* packet) const { av_packet_free(&packet); }
};
struct FrameFreer {
  void operator()(AVFrame* frame) const { av_frame_free(&frame); }
};
struct ScalerFreer {
  void operator()(SwsContext* context) const { sws_freeContext(context); }
};

class VideoSource : public FrameSource {
 public:
  // `live`: a network stream (IsLiveInput): no frame count, waits bounded by options.stream_timeout_seconds
  // and interruptible through options.stop_requested.
  VideoSource(const std::string& path, const FrameSourceOptions& options, bool live) : options_(options), live_(live) {
    info_.path = path;
    info_.format = SourceFormat::kVideo;
    // FFmpeg's own log is the host's to set: InitializeRuntime() (core/runtime.h) silences it for vmap.
    if (live_) avformat_network_init();  // reference-counted by FFmpeg; what rtsp/https need
    Open(path);
    const AVStream* stream = format_->streams[stream_index_];
    clockwise_rotation_ = ClockwiseRotation(*stream);
    const AVRational rate = stream->avg_frame_rate.num > 0 ? stream->avg_frame_rate : stream->r_frame_rate;
    info_.fps = rate.num > 0 && rate.den > 0 ? av_q2d(rate) : 0.0;
    if (!(info_.fps <= kMaxFramesPerSecond)) info_.fps = 0.0;  // a rate no camera has: unknown, as map.json says
    if (stream->nb_frames > 0) {
      frame_count_ = stream->nb_frames;
    } else if (stream->duration > 0 && info_.fps > 0) {
      frame_count_ = std::lround(stream->duration * av_q2d(stream->time_base) * info_.fps);
    }
    if (live_) frame_count_ = -1;  // what a stream announces is not what it will send
    if (frame_count_ > 0) {
      long end = options.last >= 0 ? std::min<long>(static_cast<long>(options.last) + 1, frame_count_) : frame_count_;
      info_.expected_frames = end > options.first ? (end - options.first + options.stride - 1) / options.stride : 0;
    }
  }

  std::optional<Frame> Next() override {
    for (;;) {
      if (options_.last >= 0 && position_ > options_.last) return Finish();
      if (!DecodeNext()) return Finish();
      const long index = position_++;
      if (index < options_.first || (index - options_.first) % options_.stride != 0) continue;
      const std::string size_problem = FrameSizeProblem(cv::Size(decoded_->width, decoded_->height), options_);
      if (!size_problem.empty()) {
        ++skipped_;
        spdlog::warn("{}: frame {} is {}x{}, {}; skipping it", info_.path, index, decoded_->width, decoded_->height,
                     size_problem);
        continue;
      }
      Frame frame;
      frame.color = ToBgr(*decoded_);
      // Upright as the video is meant to be shown (phones store portrait video sideways), as OpenCV does.
      if (clockwise_rotation_ == 90) cv::rotate(frame.color, frame.color, cv::ROTATE_90_CLOCKWISE);
      if (clockwise_rotation_ == 180) cv::rotate(frame.color, frame.color, cv::ROTATE_180);
      if (clockwise_rotation_ == 270) cv::rotate(frame.color, frame.color, cv::ROTATE_90_COUNTERCLOCKWISE);
      cv::cvtColor(frame.color, frame.gray, cv::COLOR_BGR2GRAY);
      frame.index = delivered_++;
      frame.source_index = static_cast<int>(index);
      frame.source_name = fmt::format("frame_{:06d}", index);
      frame.timestamp = Timestamp(index);
      FitToSequence(frame, &info_, options_, &size_warnings_);
      return frame;
    }
  }

  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return skipped_; }

 private:
  [[noreturn]] void CannotOpen(const std::string& path) const {
    if (live_) {
      throw InputError(
          fmt::format("cannot open stream '{}': no video FFmpeg can decode arrived within {:g} s; check "
                      "that the sender is running and the URL (scheme, address, port)",
                      path, options_.stream_timeout_seconds));
    }
    throw InputError("cannot open video '" + path +
                     "': it is not a video FFmpeg can decode, or it is truncated or corrupt; check the file "
                     "(ffprobe) or convert it to MP4");
  }

  // FFmpeg polls this while it waits for data: a live stream that sent nothing for the timeout, or whose run
  // was asked to end, ends (reads fail as at the end of a file). Any byte received counts, not only a whole packet:
  // opening a stream probes several seconds of it, which a slow stream (2 frames/s) takes longer than the timeout
  // to send, while it is sending all along.
  static int InterruptCallback(void* opaque) {
    VideoSource& self = *static_cast<VideoSource*>(opaque);
    if (self.options_.stop_requested && self.options_.stop_requested()) return 1;
    const auto now = std::chrono::steady_clock::now();
    if (self.watched_ && self.watched_->pb && self.watched_->pb->bytes_read != self.bytes_seen_) {
      self.bytes_seen_ = self.watched_->pb->bytes_read;
      self.last_data_ = now;
    }
    const double idle = std::chrono::duration<double>(now - self.last_data_).count();
    return idle > self.options_.stream_timeout_seconds ? 1 : 0;
  }

  void Open(const std::string& path) {
    AVFormatContext* format = avformat_alloc_context();
    if (!format) throw std::bad_alloc();
    if (live_) {
      last_data_ = std::chrono::steady_clock::now();
      format->interrupt_callback.callback = &VideoSource::InterruptCallback;
      format->interrupt_callback.opaque = this;
      watched_ = format;
    }
    if (avformat_open_input(&format, path.c_str(), nullptr, nullptr) < 0) {
      watched_ = nullptr;  // freed
      CannotOpen(path);
    }
    format_.reset(format);
    if (avformat_find_stream_info(format_.get(), nullptr) < 0) CannotOpen(path);
    const AVCodec* codec = nullptr;
    stream_index_ = av_find_best_stream(format_.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
    if (stream_index_ < 0 || !codec) CannotOpen(path);
    const AVCodecParameters* parameters = format_->streams[stream_index_]->codecpar;
    if (parameters->width <= 0 || parameters->height <= 0) CannotOpen(path);
    const std::string size_problem = FrameSizeProblem(cv::Size(parameters->width, parameters->height), options_);
    if (!size_problem.empty()) {
      throw InputError(
          fmt::format("video '{}' has frames of {}x{}, {}; scale it first (e.g. ffmpeg -i IN -vf "
                      "scale=1280:-2 OUT.mp4)",
                      path, parameters->width, parameters->height, size_problem));
    }
    codec_.reset(avcodec_alloc_context3(codec));
    if (!codec_ || avcodec_parameters_to_context(codec_.get(), parameters) < 0) CannotOpen(path);
    codec_->thread_count = 1;  // see the note at the top of the file
    if (avcodec_open2(codec_.get(), codec, nullptr) < 0) CannotOpen(path);
    packet_.reset(av_packet_alloc());
    decoded_.reset(av_frame_alloc());
    if (!packet_ || !decoded_) throw std::bad_alloc();
  }

  // Decodes the next frame into decoded_, stepping over packets that fail to decode; false at the end.
  bool DecodeNext() {
    int failures = 0;
    for (;;) {
      const int received = avcodec_receive_frame(codec_.get(), decoded_.get());
      if (received == 0) return true;
      if (received == AVERROR_EOF) return false;
      if (received != AVERROR(EAGAIN)) {
        if (!SkipDamaged(&failures)) return false;
        continue;
      }
      if (draining_) return false;
      // The decoder needs more input.
      const int read = av_read_frame(format_.get(), packet_.get());
      if (read >= 0 && live_) last_data_ = std::chrono::steady_clock::now();
      if (read < 0) {
        draining_ = true;
        avcodec_send_packet(codec_.get(), nullptr);  // flush the frames the decoder still holds
        continue;
      }
      if (packet_->stream_index == stream_index_) {
        const int sent = avcodec_send_packet(codec_.get(), packet_.get());
        if (sent < 0 && sent != AVERROR(EAGAIN) && !SkipDamaged(&failures)) {
          av_packet_unref(packet_.get());
          return false;
        }
      }
      av_packet_unref(packet_.get());
    }
  }

  // Counts a frame that could not be decoded; false when so many failed in a row that the stream ended.
  bool SkipDamaged(int* failures) {
    if (++*failures >= kMaxConsecutiveFailures) return false;
    spdlog::warn("{}: frame {} could not be decoded; skipping it", info_.path, position_);
    ++skipped_;
    ++position_;
    return true;
  }

  // The display rotation of the stream in degrees clockwise (0, 90, 180 or 270), from its display matrix.
  static int ClockwiseRotation(const AVStream& stream) {
    const uint8_t* matrix = av_stream_get_side_data(&stream, AV_PKT_DATA_DISPLAYMATRIX, nullptr);
    if (!matrix) return 0;
    // The display matrix's sign conventions are easy to get backwards: this reading turns pictures as
    // cv::VideoCapture does, which a test checks for 90, 180 and 270 degrees.
    const int degrees =
        static_cast<int>(std::lround(av_display_rotation_get(reinterpret_cast<const int32_t*>(matrix))));
    return ((degrees % 360) + 360) % 360;
  }

  cv::Mat ToBgr(const AVFrame& frame) {
    scaler_.reset(sws_getCachedContext(scaler_.release(), frame.width, frame.height,
                                       static_cast<AVPixelFormat>(frame.format), frame.width, frame.height,
                                       AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr));
    if (!scaler_) throw InputError("video '" + info_.path + "': cannot convert its pixel format to BGR");
    cv::Mat bgr(frame.height, frame.width, CV_8UC3);
    uint8_t* planes[4] = {bgr.data, nullptr, nullptr, nullptr};
    int strides[4] = {static_cast<int>(bgr.step[0]), 0, 0, 0};
    sws_scale(scaler_.get(), frame.data, frame.linesize, 0, frame.height, planes, strides);
    return bgr;
  }

  // Seconds from the stream's start, from the frame's presentation time when it has one.
  double Timestamp(long index) const {
    const AVStream* stream = format_->streams[stream_index_];
    const int64_t pts = decoded_->best_effort_timestamp;
    if (pts == AV_NOPTS_VALUE) return info_.fps > 0 ? index / info_.fps : -1.0;
    const int64_t start = stream->start_time == AV_NOPTS_VALUE ? 0 : stream->start_time;
    return (pts - start) * av_q2d(stream->time_base);
  }

  std::optional<Frame> Finish() {
    if (delivered_ == 0 && live_) {
      throw InputError(
          fmt::format("stream '{}' ended before its first frame could be decoded; check that the "
                      "sender sends video, and that key frames come often enough (e.g. ffmpeg -g 10)",
                      info_.path));
    }
    if (delivered_ == 0) {
      throw InputError("video '" + info_.path +
                       "' has no decodable frame in the requested range; it may be truncated or empty, or the first "
                       "frame asked for is past its end");
    }
    if (!warned_short_ && frame_count_ > 0 && position_ < frame_count_ && options_.last < 0) {
      // A decoder may drop a damaged frame silently; the shortfall against the container's count says so.
      warned_short_ = true;
      skipped_ += static_cast<int>(frame_count_ - position_);
      spdlog::warn("{}: the video announces {} frames but only {} could be decoded (damaged or truncated file)",
                   info_.path, frame_count_, position_);
    }
    return std::nullopt;
  }

  FrameSourceOptions options_;
  const bool live_;
  std::chrono::steady_clock::time_point last_data_;  // live: when the stream last delivered a byte
  const AVFormatContext* watched_ = nullptr;         // live: the context whose bytes InterruptCallback counts
  int64_t bytes_seen_ = 0;                           // of watched_, when last_data_ was set
  SequenceInfo info_;
  std::unique_ptr<AVFormatContext, FormatCloser> format_;
  std::unique_ptr<AVCodecContext, CodecFreer> codec_;
  std::unique_ptr<AVPacket, PacketFreer> packet_;
  std::unique_ptr<AVFrame, FrameFreer> decoded_;
  std::unique_ptr<SwsContext, ScalerFreer> scaler_;
  int stream_index_ = -1;
  int clockwise_rotation_ = 0;
  bool draining_ = false;
  long frame_count_ = -1;
  long position_ = 0;
  int delivered_ = 0;
  int skipped_ = 0;
  int size_warnings_ = 0;
  bool warned_short_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> OpenVideo(const std::string& path, const FrameSourceOptions& options) {
  return std::make_unique<VideoSource>(path, options, /*live=*/false);
}

std::unique_ptr<FrameSource> OpenStream(const std::string& url, const FrameSourceOptions& options) {
  return std::make_unique<VideoSource>(url, options, /*live=*/true);
}

}  // namespace vmap::internal
