#include "vmap_ros/debug_image.h"

#include "vmap/report/match_figure.h"

namespace vmap::ros_node {

const KeyComparison* SteeringComparison(const LocalizationResult& result) {
  if (result.to_next.key >= 0 && result.to_next.matched) return &result.to_next;
  if (result.to_key.key >= 0) return &result.to_key;
  if (result.to_next.key >= 0) return &result.to_next;
  return nullptr;
}

cv::Mat DrawDebugImage(const cv::Mat& frame, const cv::Mat& key_image, const KeyComparison* comparison,
                       const std::string& caption, int max_width) {
  Link link;  // the frame as the link's first image, the key image as its second
  if (comparison != nullptr) {
    link.similarity = comparison->similarity;
    link.num_tentative = comparison->num_tentative;
    link.num_verified = static_cast<int>(comparison->verified.size());
    link.correspondences = comparison->verified;
  }
  MatchFigureOptions options;
  options.max_width = max_width;
  options.title = caption;
  const cv::Mat key = key_image.empty() ? cv::Mat(frame.size(), CV_8UC1, cv::Scalar(128)) : key_image;
  return DrawMatchFigure(frame, key, link, options);
}

}  // namespace vmap::ros_node
