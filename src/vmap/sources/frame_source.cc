#include "vmap/sources/frame_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/folder_path.h"
#include "vmap/core/image_decode.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/option_ranges.h"
#include "vmap/sources/dataset_camera.h"
#include "vmap/sources/internal.h"

namespace vmap {
namespace fs = std::filesystem;

SourceFormat ParseSourceFormat(const std::string& name) { return ParseEnum(kSourceFormatNames, name, "format"); }

std::string SourceFormatName(SourceFormat format) { return EnumToName(kSourceFormatNames, format); }

bool AspectRatiosDiffer(const cv::Size& a, const cv::Size& b) {
  if (a.empty() || b.empty()) return false;
  const double ratio = (static_cast<double>(a.width) * b.height) / (static_cast<double>(b.width) * a.height);
  return std::abs(ratio - 1.0) > 0.01;
}

void FrameSourceOptions::Check() const {
  if (last < -1) {  // first: a message of its own, which says what -1 means
    throw OptionError("last", std::to_string(last) +
                                  " is not a frame; give a 0-based frame index, or -1 for the "
                                  "end of the sequence");
  }
  CheckFieldRanges(*this);
  if (last >= 0 && last < first) {
    throw OptionError("last", std::to_string(last) + " is before first " + std::to_string(first), {"first"});
  }
  if (max_frame_pixels < static_cast<long>(kMinFrameSide) * kMinFrameSide) {
    throw OptionError("max_frame_pixels", "must be at least " + std::to_string(kMinFrameSide * kMinFrameSide));
  }
  // The text and its sides; what a longest side makes of the frames is checked on the first frame (TargetSize).
  if (!resize.empty()) internal::ParseResize(*this);
}

namespace internal {

bool IsStreamUrl(const std::string& path) {
  for (const char* scheme : {"udp://", "rtp://", "rtsp://", "rtsps://", "tcp://", "http://", "https://", "srt://"}) {
    if (path.rfind(scheme, 0) == 0) return true;
  }
  return false;
}

}  // namespace internal

bool IsLiveInput(const std::string& path) { return internal::IsStreamUrl(path) || path.rfind("/dev/video", 0) == 0; }

std::string AbsoluteInputPath(const std::string& path) {
  std::error_code ec;
  if (path.empty() || IsLiveInput(path) || !fs::exists(path, ec)) return "";
  return NormalizedFolderPath(path).string();
}

std::string FrameSizeProblem(const cv::Size& size, const FrameSourceOptions& options) {
  if (size.width < kMinFrameSide || size.height < kMinFrameSide) {
    return "smaller than " + std::to_string(kMinFrameSide) + " pixels on a side, too small to match";
  }
  if (static_cast<long>(size.width) * size.height > options.max_frame_pixels) {
    return "more than vmap's limit of " + std::to_string(options.max_frame_pixels) + " pixels per frame";
  }
  return "";
}

cv::Mat ColorImage(const Frame& frame) {
  if (!frame.color.empty()) return frame.color;
  if (!frame.source_path.empty()) {
    // The file decoded as grey a moment ago; if it no longer does (it was replaced meanwhile), the grey frame is what
    // there is. Opened as every frame's file is: a FIFO put in its place would block the decoder.
    std::string why_not;
    const std::optional<ContainedFile> file = ContainedFile::OpenRegular(frame.source_path, &why_not);
    const cv::Mat color = file ? DecodeImageFile(*file, cv::IMREAD_COLOR, kMaxFramePixels, &why_not) : cv::Mat();
    if (!color.empty()) {
      if (color.size() == frame.gray.size()) return color;
      cv::Mat resized;
      cv::resize(color, resized, frame.gray.size(), 0, 0, cv::INTER_AREA);
      return resized;
    }
  }
  cv::Mat color;
  cv::cvtColor(frame.gray, color, cv::COLOR_GRAY2BGR);
  return color;
}

namespace internal {

bool IsImageFile(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  static const char* kExtensions[] = {".png", ".jpg",  ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm",
                                      ".pbm", ".webp", ".jp2",  ".exr", ".hdr", ".pnm",  ".ras", ".sr"};
  return std::any_of(std::begin(kExtensions), std::end(kExtensions), [&](const char* e) { return ext == e; });
}

cv::Size ParseResize(const FrameSourceOptions& options) {
  const std::string& resize = options.resize;
  const std::string range = std::to_string(kMinFrameSide) + " to " + std::to_string(kMaxResizeSide);
  int width = 0, height = 0;
  char extra = 0;
  if (std::sscanf(resize.c_str(), "%dx%d%c", &width, &height, &extra) == 2) {
    if (width < kMinFrameSide || height < kMinFrameSide || width > kMaxResizeSide || height > kMaxResizeSide) {
      throw OptionError("resize", resize + ": each side must be " + range + " pixels");
    }
    if (static_cast<long>(width) * height > options.max_frame_pixels) {
      throw OptionError("resize", resize + " has more than " + std::to_string(options.max_frame_pixels) +
                                      " pixels; choose a smaller size");
    }
    return {width, height};
  }
  int longest = 0;
  if (std::sscanf(resize.c_str(), "%d%c", &longest, &extra) == 1) {
    if (longest < kMinFrameSide || longest > kMaxResizeSide) {
      throw OptionError("resize", resize + ": the longest side must be " + range + " pixels");
    }
    return {longest, 0};
  }
  throw OptionError("resize", "'" + resize + "' is not WxH (e.g. 640x480) or a longest side (e.g. 640)");
}

cv::Size TargetSize(const cv::Size& native, const FrameSourceOptions& options) {
  if (options.resize.empty()) return native;
  const cv::Size parsed = ParseResize(options);
  if (parsed.height > 0) return parsed;
  // A longest side: the other follows the frames' own shape, which only they tell.
  const double scale = static_cast<double>(parsed.width) / std::max(native.width, native.height);
  const cv::Size target(std::max(1, static_cast<int>(std::lround(native.width * scale))),
                        std::max(1, static_cast<int>(std::lround(native.height * scale))));
  if (std::min(target.width, target.height) < kMinFrameSide ||
      static_cast<long>(target.width) * target.height > options.max_frame_pixels) {
    throw OptionError("resize", options.resize + " turns frames of " + std::to_string(native.width) + "x" +
                                    std::to_string(native.height) + " into " + std::to_string(target.width) + "x" +
                                    std::to_string(target.height) + "; give WxH with sides of " +
                                    std::to_string(kMinFrameSide) + " to " + std::to_string(kMaxResizeSide) +
                                    " pixels instead");
  }
  return target;
}

void FitFrame(Frame& frame, const cv::Size& target, const cv::Size& first_native, const FrameSourceOptions& options,
              int* warnings) {
  const cv::Size native = frame.gray.size();
  frame.native_size = native;
  if (native != first_native) {
    const std::string message = "frame " + std::to_string(frame.source_index) + " (" + frame.source_name + ") is " +
                                std::to_string(native.width) + "x" + std::to_string(native.height) +
                                " but the first frame is " + std::to_string(first_native.width) + "x" +
                                std::to_string(first_native.height);
    if (options.strict) {
      throw OptionError("strict", "is set and " + message + "; frames of one sequence must have one size");
    }
    if ((*warnings)++ < 5) spdlog::warn("{}; resizing it to the first frame's size", message);
  }
  if (native == target) return;
  frame.resized = true;
  const int interpolation = target.area() < native.area() ? cv::INTER_AREA : cv::INTER_LINEAR;
  cv::resize(frame.gray, frame.gray, target, 0, 0, interpolation);
  if (!frame.color.empty()) cv::resize(frame.color, frame.color, target, 0, 0, interpolation);
}

void FitToSequence(Frame& frame, SequenceInfo* info, const FrameSourceOptions& options, int* warnings) {
  if (frame.index == 0) {
    info->native_size = frame.gray.size();
    info->frame_size = TargetSize(info->native_size, options);
  }
  FitFrame(frame, info->frame_size, info->native_size, options, warnings);
}

}  // namespace internal

namespace {

std::unique_ptr<FrameSource> OpenDetected(const std::string& path, const fs::path& p, SourceFormat format,
                                          const FrameSourceOptions& options);

// Attaches the camera to a source's SequenceInfo once the first frame tells the frames' size: the
// intrinsics are checked against the native size and scaled to the delivered (--resize) size.
class CameraSource : public FrameSource {
 public:
  // `given`: the user's --camera; else one vmap found beside the input (intrinsics.txt, calib.txt, a CameraInfo).
  CameraSource(std::unique_ptr<FrameSource> inner, Camera camera, bool given)
      : inner_(std::move(inner)), camera_(std::move(camera)), given_(given), info_(inner_->info()) {}

  std::optional<Frame> Next() override {
    std::optional<Frame> frame = inner_->Next();
    info_ = inner_->info();
    if (frame && !scaled_) {
      try {
        scaled_ = CameraForFrames(camera_, info_.native_size, info_.frame_size);
      } catch (const OptionError& error) {
        if (given_) throw;
        // Not the user's --camera, which an OptionError of "camera" would blame: the file found is at fault.
        throw InputError("the camera found with the input " + error.problem() +
                         "; correct it, or give the camera yourself (--camera; none: no camera)");
      }
    }
    info_.camera = scaled_;
    return frame;
  }
  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return inner_->skipped_frames(); }

 private:
  std::unique_ptr<FrameSource> inner_;
  Camera camera_;
  bool given_;
  std::optional<Camera> scaled_;
  SequenceInfo info_;
};

std::unique_ptr<FrameSource> OpenDetectedFrameSource(const std::string& path, const FrameSourceOptions& options) {
  if (IsLiveInput(path)) {
    std::unique_ptr<FrameSource> live =
        internal::IsStreamUrl(path) ? internal::OpenStream(path, options) : internal::OpenV4l2Camera(path, options);
    if (options.camera.empty() || options.camera == "none") return live;
    return std::make_unique<CameraSource>(std::move(live), ParseCameraOption(options.camera), true);
  }
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    throw InputError("input '" + path +
                     "' does not exist; give a video file, an image folder, a TUM/EuRoC/KITTI "
                     "sequence or a ROS bag / MCAP recording");
  }
  const fs::path p(path);
  // Before anything opens it: a FIFO would block the reader until something writes to it, a device never ends.
  const fs::file_status status = fs::status(p, ec);
  if (!fs::is_directory(status) && !fs::is_regular_file(status)) {
    throw InputError("input '" + path +
                     "' is not a regular file or a folder (a FIFO, a device or a socket); give a video file, an image "
                     "folder, a dataset sequence or a recording");
  }
  if (!fs::is_directory(p) && internal::IsImageFile(path) && options.format == SourceFormat::kAuto) {
    if (!options.allow_single_image) {
      throw InputError("input '" + path + "' is a single image; pass the folder that holds the sequence's images");
    }
    // One image: no dataset around it to take intrinsics from; --camera still applies.
    std::unique_ptr<FrameSource> single =
        internal::OpenImageList({{path, -1.0}}, path, SourceFormat::kImageFolder, options);
    if (options.camera.empty() || options.camera == "none") return single;
    return std::make_unique<CameraSource>(std::move(single), ParseCameraOption(options.camera), true);
  }
  const SourceFormat format = DetectSourceFormat(path, options.format);
  std::optional<Camera> recording_camera;  // a recording's CameraInfo, read only when no --camera overrides it
  std::unique_ptr<FrameSource> source;
  try {
    source = format == SourceFormat::kRecording
                 ? internal::OpenRecordingSource(path, options, options.camera.empty() ? &recording_camera : nullptr)
                 : OpenDetected(path, p, format, options);
  } catch (const OptionError&) {
    throw;
  } catch (const InputError& error) {
    // A format given that the input is not ("--format tum video.mp4" said "line 1 is not 'timestamp filename'"): the
    // format is at fault where the input looks like another.
    const SourceFormat detected = DetectSourceFormat(path, SourceFormat::kAuto);
    if (options.format == SourceFormat::kAuto || detected == format) throw;
    throw OptionError("format", SourceFormatName(format) + ": " + error.what() + "; '" + path + "' looks like " +
                                    SourceFormatName(detected) + ": give that format, or leave the format out");
  }
  std::optional<Camera> camera;
  if (options.camera.empty()) {
    camera = format == SourceFormat::kRecording ? recording_camera : FindDatasetCamera(path, format);
  } else if (options.camera != "none")
    camera = ParseCameraOption(options.camera);
  if (!camera) return source;
  return std::make_unique<CameraSource>(std::move(source), *camera, !options.camera.empty());
}

std::unique_ptr<FrameSource> OpenDetected(const std::string& path, const fs::path& p, SourceFormat format,
                                          const FrameSourceOptions& options) {
  switch (format) {
    case SourceFormat::kVideo:
      if (fs::is_directory(p)) {
        throw OptionError("format", "video: input '" + path + "' is a folder, not a video; drop it");
      }
      return internal::OpenVideo(path, options);
    case SourceFormat::kImageFolder:
      return internal::OpenImageList(internal::ListImageFolder(path), path, format, options);
    case SourceFormat::kTum:
      return internal::OpenImageList(internal::ListTum(fs::is_directory(p) ? (p / "rgb.txt").string() : path), path,
                                     format, options);
    case SourceFormat::kEuroc: {
      std::string csv = path;
      if (fs::is_directory(p))
        csv =
            fs::exists(p / "mav0/cam0/data.csv") ? (p / "mav0/cam0/data.csv").string() : (p / "cam0/data.csv").string();
      return internal::OpenImageList(internal::ListEuroc(csv), path, format, options);
    }
    case SourceFormat::kKitti:
      return internal::OpenImageList(internal::ListKitti(path), path, format, options);
    case SourceFormat::kRecording:  // opened by OpenDetectedFrameSource, which also reads its camera
    case SourceFormat::kAuto:
      break;
  }
  throw OptionError(
      "format", "auto cannot tell the layout of '" + path + "'; give its layout: video, images, tum, euroc or kitti");
}

}  // namespace

std::unique_ptr<FrameSource> OpenFrameSource(const std::string& path, const FrameSourceOptions& options) {
  options.Check();
  // The layouts read folders and list files: a file system error (a folder that cannot be listed, a file that
  // cannot be inspected) is reported with the input's name.
  return RethrowAsInputError(
      [&] {
        return ErrorContext{"cannot read the input '" + path + "'", "check that it exists and that you may read it"};
      },
      [&] { return OpenDetectedFrameSource(path, options); });
}

void FrameSourceOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section(kInputSection);
  visitor.Visit(OptionField{"format", "--format", "Input layout: "}.ListingNames(),
                EnumField(format, kSourceFormatNames, ParseSourceFormat));
  visitor.Visit(OptionField{"first", "--first", "First frame (0-based)"}.AtLeast(0), first);
  visitor.Visit(
      OptionField{"last", "--last", "Last frame, inclusive (-1 = end)"}.AtLeast(0).Or(-1).Meaning("-1: to the end"),
      last);
  visitor.Visit(OptionField{"stride", "--stride", "Use every N-th frame"}.AtLeast(1), stride);
  visitor.Visit(OptionField{"resize", "--resize", "Resize frames: WxH, or the longest side (e.g. 640)"}.HideDefault(),
                resize);
  visitor.Visit({"strict", "--strict", "Frames of a different size are an error, not a warning"}, strict);
  // map.json names the default, the intrinsics that come with the input, "input".
  visitor.Visit(
      OptionField{"camera", "--camera",
                  "Intrinsics: fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]] (pixels, native frame size) or a calibration "
                  "file (OpenCV YAML/JSON, EuRoC sensor.yaml, KITTI calib.txt, intrinsics.txt); 'none' ignores "
                  "the input's own. Default: the input's own, if any"}
          .HideDefault()
          .EmptyAs("input"),
      camera);
  visitor.Visit(OptionField{"topic", "--topic",
                            "Recordings (ROS bag, rosbag2, MCAP): the image topic (Image or CompressedImage). Default: "
                            "the only one; `vmap info RECORDING` lists them"}
                    .HideDefault()
                    .OmitEmpty(),
                topic);
  visitor.Visit(OptionField{"camera_topic", "--camera-topic",
                            "Recordings: the CameraInfo topic. Default: camera_info beside the image topic"}
                    .HideDefault()
                    .OmitEmpty(),
                camera_topic);
  visitor.Visit(OptionField{"stream_timeout_seconds", "--stream-timeout",
                            "Live inputs: seconds in which nothing arrives after which the stream has ended (and the "
                            "longest wait for it to start sending)"}
                    .NotRecorded()
                    .Within(0, 3600)
                    .ExcludingMin()
                    .Unit("s"),
                stream_timeout_seconds);
}

}  // namespace vmap
