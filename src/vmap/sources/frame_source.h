#pragma once
// Frame sources: a sequence of images streamed one at a time from a video file, an image folder, or a
// dataset layout (TUM RGB-D, EuRoC, KITTI odometry). Memory stays flat however long the sequence is.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/core/natural_less.h"  // NaturalLess, which the layouts sort by
#include "vmap/core/option_fields.h"
#include "vmap/geometry/camera.h"
#include "vmap/sources/odometry_sample.h"

namespace vmap {

// kRecording: a robot's recording, a ROS 1 .bag, a rosbag2 folder or .db3, or an .mcap file (recording_source.h).
enum class SourceFormat { kAuto, kVideo, kImageFolder, kTum, kEuroc, kKitti, kRecording };
inline constexpr EnumName<SourceFormat> kSourceFormatNames[] = {
    {SourceFormat::kAuto, "auto"},          {SourceFormat::kVideo, "video"},
    {SourceFormat::kImageFolder, "images"}, {SourceFormat::kTum, "tum"},
    {SourceFormat::kEuroc, "euroc"},        {SourceFormat::kKitti, "kitti"},
    {SourceFormat::kRecording, "recording"}};

SourceFormat ParseSourceFormat(const std::string& name);
std::string SourceFormatName(SourceFormat format);

// Frames narrower or lower than this are skipped: no matcher finds anything in them (ORB's border alone is
// 31 px, LoFTR's coarse cells are 8 or 16 px), and OpenCV's image pyramids fail on them.
inline constexpr int kMinFrameSide = 32;
// --resize accepts sides in [kMinFrameSide, kMaxResizeSide].
inline constexpr int kMaxResizeSide = 16384;
// The default of FrameSourceOptions::max_frame_pixels: 8192 x 8192 (64 megapixels).
inline constexpr long kMaxFramePixels = 8192L * 8192L;
// A timestamp beyond this many seconds (31,700 years) is not one: nanoseconds or microseconds given as seconds. A map
// records its key images' stamps within it, and a source refuses a list of frames that has one beyond.
inline constexpr double kMaxTimestampSeconds = 1e12;
// A frame rate above this is not a camera's: the sources report 0 (unknown) instead, as map.json records it.
inline constexpr double kMaxFramesPerSecond = 1e6;

struct FrameSourceOptions {
  SourceFormat format = SourceFormat::kAuto;
  // Frames [first, last] of the sequence (0-based, inclusive; last = -1 means to the end), every stride-th.
  int first = 0;
  int last = -1;
  int stride = 1;
  // Resize: "" keeps the native size, "640x480" a fixed size, "640" the longest side (aspect kept).
  std::string resize;
  // Frames whose size differs from the first frame's are resized to it with a warning; with strict, an error.
  bool strict = false;
  // A decoded frame with more pixels than this is skipped with a warning and counted (skipped_frames), as is
  // one with a side under kMinFrameSide: 8192 x 8192 (64 megapixels) is more than any camera's video frame,
  // and bounds the memory a hostile image can take once decoded.
  long max_frame_pixels = kMaxFramePixels;
  // The camera: "" = the intrinsics that come with the input, if any (see dataset_camera.h); "none" = no
  // camera; otherwise "fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]]" or a calibration file (--camera).
  std::string camera;
  // A single image file is a sequence of one frame (vmap localize takes one query image); otherwise it is an
  // error, since one frame makes no map.
  bool allow_single_image = false;
  // Live inputs (IsLiveInput): polled while the source waits for data; when it returns true the source ends
  // as if the input had ended (`vmap build --until-interrupted` passes InputEndRequested).
  std::function<bool()> stop_requested;
  // Live inputs: a stream that sends nothing for this long has ended (a network sender that stopped, a
  // camera that was unplugged); also how long opening one may take.
  double stream_timeout_seconds = 10.0;
  // Recordings: the image topic ("" = the recording's only one) and its CameraInfo topic ("" = the image
  // topic's sibling camera_info, as image_transport pairs them).
  std::string topic;
  std::string camera_topic;

  // Which frames of which input, as map.json records them: format, first, last, stride, resize, strict and
  // camera ("input" for the input's own intrinsics, the default ""), and topic and camera_topic when set. The
  // rest are limits and callbacks of a run (stream_timeout_seconds has its flag).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct Frame {
  int index = 0;            // position in the processed sequence: 0, 1, 2, ...
  int source_index = 0;     // position in the input (differs with first/stride)
  double timestamp = -1.0;  // seconds, from the dataset or the video; -1 when the format has none
  std::string source_name;  // the image file name, or "frame_000123" for video
  std::string source_path;  // the image file, empty for video
  cv::Mat gray;             // 8-bit, one channel: what the matchers see
  cv::Mat color;            // 8-bit BGR when the input is colour; may be empty (then use gray)
  bool resized = false;     // the decoded image was resized (--resize, or a size that differs from the first)
  cv::Size native_size;     // the decoded image's size, before any resizing; empty when not known
  // The robot's odometry pose at the frame's time, where a repeat run has odometry beside its frames (none from the
  // input itself): the localizer's motion model moves by the distance driven (localization/motion_pace.h).
  std::optional<OdometrySample> odometry;
};

// Whether images of these sizes have other shapes (aspect ratios more than 1 % apart): resized to one size, one of
// them is stretched, so that a camera describing one does not describe the other. False when either is empty.
bool AspectRatiosDiffer(const cv::Size& a, const cv::Size& b);

struct SequenceInfo {
  std::string path;  // as given by the user
  // `path` made absolute where it named a file or folder when it was read (empty for a live input): a relative path
  // is relative to the folder it was given in, and a map records both (AbsoluteInputPath).
  std::string absolute_path;
  SourceFormat format = SourceFormat::kAuto;
  long expected_frames = -1;  // frames that will be delivered (after first/last/stride); -1 if unknown
  cv::Size native_size;       // the first frame's size as stored
  cv::Size frame_size;        // the size of delivered frames
  double fps = 0.0;           // video only
  // The camera of the delivered frames (scaled with --resize), known once the first frame is read; empty
  // when the input has no intrinsics and none were given.
  std::optional<Camera> camera;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame, or nullopt at the end. Throws InputError on input that cannot be read at all.
  virtual std::optional<Frame> Next() = 0;
  virtual const SequenceInfo& info() const = 0;
  // Frames that could not be used and were skipped so far: a frame that does not decode (a corrupt frame
  // inside a video, a damaged image file), or one of a degenerate size or too many pixels.
  virtual int skipped_frames() const { return 0; }
};

// Whether `path` names a live input, with no known end or frame count: a network stream URL (udp://, rtp://,
// rtsp://, rtsps://, tcp://, http://, https://, srt://), read through FFmpeg, or a V4L2 camera device
// (/dev/video0), read through OpenCV. OpenFrameSource opens these too.
bool IsLiveInput(const std::string& path);

// `path` made absolute and normal where it names a file or folder from here; "" for a live input or one not found.
std::string AbsoluteInputPath(const std::string& path);

// Detects the layout of `path` (or uses options.format) and opens it. Throws InputError with a message
// that names the path and says what to do when it cannot.
std::unique_ptr<FrameSource> OpenFrameSource(const std::string& path, const FrameSourceOptions& options = {});

// Why a decoded image of this size cannot be a frame (a side under kMinFrameSide, or more than
// options.max_frame_pixels), or "" when it can.
std::string FrameSizeProblem(const cv::Size& size, const FrameSourceOptions& options = {});

// The frame as a BGR image (re-reads a colour image file when the frame only kept the grey one).
cv::Mat ColorImage(const Frame& frame);

}  // namespace vmap
