#include "vmap/map/visual_map.h"

#include <algorithm>
#include <numeric>

#include "vmap/core/error.h"

namespace vmap {

void SplitCorrespondences(const std::vector<Correspondence>& correspondences, std::vector<cv::Point2f>* points0,
                          std::vector<cv::Point2f>* points1, int count) {
  const size_t n = count < 0 ? correspondences.size() : std::min(correspondences.size(), static_cast<size_t>(count));
  points0->clear();
  points1->clear();
  points0->reserve(n);
  points1->reserve(n);
  for (size_t i = 0; i < n; ++i) {
    points0->push_back(correspondences[i].p0);
    points1->push_back(correspondences[i].p1);
  }
}

QualityMean ParseQualityMean(const std::string& name) { return ParseEnum(kQualityMeanNames, name, "quality mean"); }

std::string QualityMeanName(QualityMean mean) { return EnumToName(kQualityMeanNames, mean); }

double MapQuality(int num_frames, int num_key_images, const std::vector<double>& link_similarities, QualityMean mean) {
  if (num_frames <= 0) return 0.0;
  const double compression = 1.0 - static_cast<double>(num_key_images) / num_frames;
  const double similarity =
      link_similarities.empty()
          ? 0.0
          : std::accumulate(link_similarities.begin(), link_similarities.end(), 0.0) / link_similarities.size();
  if (mean == QualityMean::kArithmetic) return 0.5 * (compression + similarity);
  return compression + similarity > 0 ? 2.0 * compression * similarity / (compression + similarity) : 0.0;
}

MapStatistics ComputeStatistics(const VisualMap& map, QualityMean mean) {
  MapStatistics s;
  s.num_frames = map.num_frames;
  s.num_key_images = static_cast<int>(map.key_images.size());
  std::vector<double> similarities;
  long total_verified = 0;
  for (const Link& l : map.links) {
    similarities.push_back(l.similarity);
    total_verified += l.num_verified;
    s.below_tau_links += l.below_tau ? 1 : 0;
  }
  if (!map.links.empty()) {
    auto [lo, hi] = std::minmax_element(map.links.begin(), map.links.end(),
                                        [](const Link& a, const Link& b) { return a.num_verified < b.num_verified; });
    s.min_verified = lo->num_verified;
    s.max_verified = hi->num_verified;
    s.mean_verified = static_cast<double>(total_verified) / map.links.size();
    s.mean_similarity = std::accumulate(similarities.begin(), similarities.end(), 0.0) / similarities.size();
  }
  s.quality = MapQuality(s.num_frames, s.num_key_images, similarities, mean);
  return s;
}

}  // namespace vmap
