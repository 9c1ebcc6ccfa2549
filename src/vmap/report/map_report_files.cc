#include "vmap/report/map_report_files.h"

#include <algorithm>
#include <map>
#include <memory>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/report/html_page.h"
#include "vmap/report/match_figure.h"

namespace vmap::report {
namespace fs = std::filesystem;

namespace {

// The key images in order as a short video: H.264 in MP4 where OpenCV's FFmpeg has an encoder for it, else
// VP9 in WebM; both play in current browsers. Without either, the page keeps only the step-through player.
class RouteVideo {
 public:
  // `shown`: the folder the video is in once the report is in place, for messages.
  RouteVideo(const fs::path& directory, const fs::path& shown, const cv::Size& frame_size, double fps)
      // H.264 with 4:2:0 sampling needs even sides.
      : size_(std::max(2, frame_size.width & ~1), std::max(2, frame_size.height & ~1)), shown_(shown) {
    const std::pair<const char*, int> candidates[] = {
        {kRouteVideoNames[0], cv::VideoWriter::fourcc('a', 'v', 'c', '1')},
        {kRouteVideoNames[1], cv::VideoWriter::fourcc('V', 'P', '9', '0')}};
    for (const auto& [name, fourcc] : candidates) {
      try {
        if (writer_.open((directory / name).string(), cv::CAP_FFMPEG, fourcc, fps, size_)) {
          file_name_ = name;
          path_ = directory / name;
          return;
        }
      } catch (const cv::Exception&) {
      }
      std::error_code ignored;
      fs::remove(directory / name, ignored);
    }
  }

  void Add(const cv::Mat& image, const std::string& label) {
    if (!writer_.isOpened()) return;
    cv::Mat frame;
    cv::resize(image, frame, size_, 0, 0, cv::INTER_AREA);
    const double scale = std::clamp(size_.width / 700.0, 0.35, 1.0);
    cv::putText(frame, label, cv::Point(7, size_.height - 9), cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar::all(0), 3,
                cv::LINE_AA);
    cv::putText(frame, label, cv::Point(7, size_.height - 9), cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar::all(255), 1,
                cv::LINE_AA);
    writer_.write(frame);
    ++frames_;
  }

  // Closes the file; false (and no file) when nothing usable was written. Throws InputError naming the video when
  // it does not read back whole: cv::VideoWriter ignores failed writes (a full disk, the file size limit), and a
  // video cut short would be put in place as the report's.
  bool Finish() {
    if (!writer_.isOpened()) return false;
    writer_.release();
    std::error_code ec;
    if (frames_ == 0 || fs::file_size(path_, ec) == 0 || ec) {
      fs::remove(path_, ec);
      return false;
    }
    const int read_back = FramesReadBack();
    if (read_back == frames_) return true;
    fs::remove(path_, ec);
    throw InputError(fmt::format(
        "cannot write the route video '{}': {} of its {} frames read back (a full disk, or the file size limit?); "
        "free some space, or leave the video out with --no-video",
        (shown_ / file_name_).string(), read_back, frames_));
  }

  const std::string& file_name() const { return file_name_; }
  const cv::Size& size() const { return size_; }

 private:
  // Decoded, not taken from the container's frame count, which a file cut short may still claim whole.
  int FramesReadBack() const {
    try {
      cv::VideoCapture capture(path_.string(), cv::CAP_FFMPEG);
      int count = 0;
      for (cv::Mat frame; capture.isOpened() && capture.read(frame) && !frame.empty();) ++count;
      return count;
    } catch (const cv::Exception&) {
      return 0;
    }
  }

  cv::Size size_;
  fs::path shown_;
  cv::VideoWriter writer_;
  std::string file_name_;
  fs::path path_;
  int frames_ = 0;
};

}  // namespace

std::string ThumbnailFile(int key) { return std::string(kThumbnailsFolder) + "/" + Numbered(key); }

std::string MatchFigureFile(int link) { return std::string(kMatchFiguresFolder) + "/" + Numbered(link); }

bool IsMapReportFile(const std::string& name) {
  if (name == kThumbnailsFolder || name == kMatchFiguresFolder) return true;
  for (const char* video : kRouteVideoNames) {
    if (name == video) return true;
  }
  return false;
}

MapReportFiles WriteMapReportFiles(const fs::path& map_directory, const VisualMap& map, const MapReportOptions& options,
                                   const fs::path& directory) {
  fs::create_directory(directory / kThumbnailsFolder);  // not create_directories: see AtomicOutputDirectory::path()
  fs::create_directory(directory / kMatchFiguresFolder);

  // Consecutive links share a key image: keep the last two decoded. (cv::Mat copies share the pixels, so a
  // returned image stays valid after it leaves the cache.)
  std::map<int, cv::Mat> cache;
  auto key_image = [&](int index) -> cv::Mat {
    auto it = cache.find(index);
    if (it != cache.end()) return it->second;
    while (cache.size() >= 2) cache.erase(cache.begin());
    return cache[index] = ReadKeyImage(map_directory, map.key_images[index]);
  };

  MapReportFiles assets;
  std::unique_ptr<RouteVideo> video;
  for (size_t i = 0; i < map.key_images.size(); ++i) {
    const cv::Mat thumb = ScaledToWidth(key_image(static_cast<int>(i)), options.thumbnail_width);
    WriteJpeg(directory / ThumbnailFile(static_cast<int>(i)), thumb, options.jpeg_quality);
    assets.thumbnail_sizes.push_back(thumb.size());
    if (i == 0 && options.route_video && map.key_images.size() > 1) {
      video = std::make_unique<RouteVideo>(directory, map_directory / kReportAssetsDirectory, thumb.size(),
                                           options.route_fps);
    }
    if (video) {
      video->Add(thumb, "key " + std::to_string(i) + "  frame " + std::to_string(map.key_images[i].frame_index));
    }
  }
  if (video && video->Finish()) {
    assets.video_file = video->file_name();
    assets.video_size = video->size();
  }
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    MatchFigureOptions figure_options;
    figure_options.max_width = options.figure_width;
    figure_options.title = "link " + std::to_string(i) + ": " + LinkTitle(map, static_cast<int>(i));
    const cv::Mat figure = DrawMatchFigure(key_image(l.from_key), key_image(l.to_key), l, figure_options);
    WriteJpeg(directory / MatchFigureFile(static_cast<int>(i)), figure, options.jpeg_quality);
    assets.figure_sizes.push_back(figure.size());
  }
  return assets;
}

}  // namespace vmap::report
