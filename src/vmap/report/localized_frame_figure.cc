// A localized frame beside the images it was compared with (localization reports).

#include "vmap/report/localized_frame_figure.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "vmap/map/map_io.h"
#include "vmap/report/html_page.h"

namespace vmap::report {
namespace {

cv::Mat ToHeight(const cv::Mat& image, int height) {
  if (image.rows == height) return image;
  cv::Mat scaled;
  const int width = std::max(1, static_cast<int>(std::lround(static_cast<double>(image.cols) * height / image.rows)));
  cv::resize(image, scaled, cv::Size(width, height), 0, 0, height < image.rows ? cv::INTER_AREA : cv::INTER_LINEAR);
  return scaled;
}

}  // namespace

ComparedImage ReadComparedImage(const std::filesystem::path& map_directory, const VisualMap& map, int key, const KeyComparison& c) {
  KeyImage image = map.key_images.at(key);
  std::string label;
  for (const Experience& e : map.experiences) {
    if (c.key != key || e.id != c.experience) continue;
    for (const ExperienceView& view : e.views) {
      if (view.key != key) continue;
      image.image_file = view.image_file;
      label = fmt::format(" (experience {})", e.id);
    }
  }
  return {ReadKeyImage(map_directory, image), label};
}

cv::Mat DrawLocalizedFrame(const cv::Mat& frame, const ComparedImage& key, const ComparedImage& next, const LocalizationResult& r,
                 int width) {
  const int height = frame.rows;
  std::vector<cv::Mat> panels = {frame};
  std::vector<std::string> labels = {fmt::format("frame {} ({})", r.frame_index, LocalizationStatusName(r.status))};
  if (!key.image.empty()) {
    panels.push_back(ToHeight(key.image, height));
    labels.push_back(
        fmt::format("key {}{}  S {:.2f}  {} verified", r.key, key.label, r.to_key.similarity, r.to_key.num_verified));
  }
  if (!next.image.empty()) {
    panels.push_back(ToHeight(next.image, height));
    labels.push_back(fmt::format("next {}{}  S {:.2f}  {} verified", r.next_key, next.label, r.to_next.similarity,
                                 r.to_next.num_verified));
  }
  const int gap = 6;
  int total = 0;
  for (const cv::Mat& p : panels) total += p.cols + gap;
  cv::Mat canvas(height, total - gap, CV_8UC3, cv::Scalar(255, 255, 255));
  int x = 0;
  for (size_t i = 0; i < panels.size(); ++i) {
    cv::Mat roi = canvas(cv::Rect(x, 0, panels[i].cols, height));
    if (panels[i].channels() == 1)
      cv::cvtColor(panels[i], roi, cv::COLOR_GRAY2BGR);
    else
      panels[i].copyTo(roi);
    const double scale = std::max(0.4, height / 600.0);
    const int baseline_y = static_cast<int>(22 * scale) + 4;
    cv::rectangle(canvas, cv::Rect(x, 0, panels[i].cols, baseline_y + 6), cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(canvas, labels[i], cv::Point(x + 6, baseline_y), cv::FONT_HERSHEY_SIMPLEX, 0.6 * scale,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    x += panels[i].cols + gap;
  }
  if (r.status == LocalizationStatus::kLost) {
    cv::rectangle(canvas, cv::Rect(0, 0, canvas.cols, canvas.rows), cv::Scalar(40, 40, 214), 6);
  }
  return ScaledToWidth(canvas, width);
}

}  // namespace vmap::report
