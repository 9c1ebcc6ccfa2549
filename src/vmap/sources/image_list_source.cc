// A frame source over a list of image files (image folder, TUM, EuRoC, KITTI).

#include <filesystem>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/image_decode.h"
#include "vmap/core/image_header.h"
#include "vmap/sources/internal.h"

namespace vmap::internal {
namespace {

class ImageListSource : public FrameSource {
 public:
  ImageListSource(std::vector<ImageEntry> entries, const std::string& path, SourceFormat format,
                  const FrameSourceOptions& options)
      : entries_(std::move(entries)), options_(options) {
    info_.path = path;
    info_.format = format;
    next_ = options.first;
    end_ = options.last >= 0 ? std::min<long>(static_cast<long>(options.last) + 1, entries_.size())
                             : static_cast<long>(entries_.size());
    if (next_ >= end_) {
      throw OptionError("first", std::to_string(options.first) + " leaves none of the " +
                                     std::to_string(entries_.size()) + " frames of '" + path + "'");
    }
    info_.expected_frames = (end_ - next_ + options.stride - 1) / options.stride;
    // Refused before any work: a map of such stamps could not be read back (map.json's own bound).
    for (const ImageEntry& entry : entries_) {
      if (entry.timestamp > kMaxTimestampSeconds) {
        throw InputError(
            fmt::format("'{}': the timestamp of '{}' is {} s, more than {:g} s (31,700 years): are the timestamps in "
                        "nanoseconds or microseconds? Give them in seconds",
                        path, entry.path, entry.timestamp, kMaxTimestampSeconds));
      }
    }
  }

  std::optional<Frame> Next() override {
    while (next_ < end_) {
      const long index = next_;
      next_ += options_.stride;
      const ImageEntry& entry = entries_[index];
      Frame frame;
      // Only a regular file (a FIFO would block the decoder), and only of a size a frame may have, read from
      // its header before anything is decoded.
      std::string why_not;
      const std::optional<ContainedFile> file = ContainedFile::OpenRegular(entry.path, &why_not);
      if (!file) {
        Skip(entry, "it " + why_not);
        continue;
      }
      if (const std::optional<cv::Size> announced = ImageHeaderSize(*file)) {
        const std::string problem = FrameSizeProblem(*announced, options_);
        if (!problem.empty()) {
          Skip(entry, "its header announces " + std::to_string(announced->width) + "x" +
                          std::to_string(announced->height) + ", " + problem);
          continue;
        }
      }
      // Grey straight from the decoder, as the matchers' reference implementations read images.
      frame.gray = DecodeImageFile(*file, cv::IMREAD_GRAYSCALE, options_.max_frame_pixels, &why_not);
      if (frame.gray.empty()) {
        Skip(entry, "it " + why_not);
        continue;
      }
      const std::string size_problem = FrameSizeProblem(frame.gray.size(), options_);
      if (!size_problem.empty()) {
        Skip(entry,
             "it is " + std::to_string(frame.gray.cols) + "x" + std::to_string(frame.gray.rows) + ", " + size_problem);
        continue;
      }
      frame.index = delivered_++;
      frame.source_index = static_cast<int>(index);
      frame.timestamp = entry.timestamp;
      frame.source_path = entry.path;
      frame.source_name = std::filesystem::path(entry.path).filename().string();
      FitToSequence(frame, &info_, options_, &size_warnings_);
      return frame;
    }
    if (delivered_ == 0) {
      throw InputError("none of the " + std::to_string(entries_.size()) + " images of '" + info_.path +
                       "' could be used (see the warnings above); check the files");
    }
    return std::nullopt;
  }

  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return skipped_; }

 private:
  void Skip(const ImageEntry& entry, const std::string& why) {
    ++skipped_;
    spdlog::warn("'{}': {}; skipping it", entry.path, why);
  }

  std::vector<ImageEntry> entries_;
  FrameSourceOptions options_;
  SequenceInfo info_;
  long next_ = 0;
  long end_ = 0;
  int delivered_ = 0;
  int skipped_ = 0;
  int size_warnings_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> OpenImageList(std::vector<ImageEntry> entries, const std::string& path,
                                           SourceFormat format, const FrameSourceOptions& options) {
  return std::make_unique<ImageListSource>(std::move(entries), path, format, options);
}

}  // namespace vmap::internal
