#pragma once
// Pieces shared by the frame source implementations (not part of the public interface).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vmap/sources/frame_source.h"

namespace vmap::internal {

// One image of a list-based layout (image folder, TUM, EuRoC, KITTI).
struct ImageEntry {
  std::string path;
  double timestamp = -1.0;
};

// Parsed layouts. Each throws InputError naming the file and line when it is malformed, and checks that
// every listed image exists.
std::vector<ImageEntry> ListImageFolder(const std::string& directory);
std::vector<ImageEntry> ListTum(const std::string& rgb_txt);
std::vector<ImageEntry> ListEuroc(const std::string& data_csv);
std::vector<ImageEntry> ListKitti(const std::string& sequence_directory);

std::unique_ptr<FrameSource> OpenImageList(std::vector<ImageEntry> entries, const std::string& path,
                                           SourceFormat format, const FrameSourceOptions& options);
std::unique_ptr<FrameSource> OpenVideo(const std::string& path, const FrameSourceOptions& options);
// A network stream URL (IsLiveInput), through FFmpeg like a video file, with no frame count.
std::unique_ptr<FrameSource> OpenStream(const std::string& url, const FrameSourceOptions& options);
// A V4L2 camera device such as /dev/video0.
std::unique_ptr<FrameSource> OpenV4l2Camera(const std::string& device, const FrameSourceOptions& options);
bool IsStreamUrl(const std::string& path);
// A recording (recording_source.h). `camera`, when given, receives the camera of its CameraInfo topic.
std::unique_ptr<FrameSource> OpenRecordingSource(const std::string& path, const FrameSourceOptions& options,
                                                 std::optional<Camera>* camera);

// The --resize text, checked without the frames: {W, H} for WxH (each side in range, within max_frame_pixels), {L, 0}
// for a longest side L in range. Throws OptionError naming the text otherwise.
cv::Size ParseResize(const FrameSourceOptions& options);

// Size frames are delivered at, given the first frame's native size and the --resize option. Throws
// OptionError when `resize` is malformed or out of its range, or would make these frames degenerate.
cv::Size TargetSize(const cv::Size& native, const FrameSourceOptions& options);

// Brings a decoded frame to the sequence's frame size: the --resize target, or the first frame's size for
// a frame that differs (a warning, or an error with strict).
void FitFrame(Frame& frame, const cv::Size& target, const cv::Size& first_native, const FrameSourceOptions& options,
              int* warnings);

// The first frame (index 0) sets the sequence's native and delivered sizes in `info`; every frame is then
// brought to them with FitFrame.
void FitToSequence(Frame& frame, SequenceInfo* info, const FrameSourceOptions& options, int* warnings);

bool IsImageFile(const std::string& path);

}  // namespace vmap::internal
