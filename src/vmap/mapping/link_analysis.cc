#include "vmap/mapping/link_analysis.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace vmap {

void LinkAnalysisOptions::Check() const {
  pose.Check();
  homography.Check();
}

void AnalyzeLink(Link& link, const Camera* camera, const LinkAnalysisOptions& options) {
  link.has_pose = false;
  link.R = cv::Matx33d::eye();
  link.t = cv::Vec3d();
  link.pose_inliers = 0;
  link.parallax = -1.0;
  link.parallax_without_rotation = false;
  link.homography_share = -1.0;
  link.planar = false;
  if (!link.has_fundamental || link.num_verified <= 0) return;

  std::vector<cv::Point2f> verified_from, verified_to, all_from, all_to;
  for (size_t i = 0; i < link.correspondences.size(); ++i) {
    const Correspondence& c = link.correspondences[i];
    if (static_cast<int>(i) < link.num_verified) {
      verified_from.push_back(c.p0);
      verified_to.push_back(c.p1);
    }
    all_from.push_back(c.p0);
    all_to.push_back(c.p1);
  }

  if (camera) {
    RelativePose pose;
    if (options.pose.method == PoseMethod::kFromFundamental) {
      pose = PoseFromFundamental(link.F, *camera, verified_from, verified_to);
    } else {
      // The pose of F is one more start: where it is right and USAC's are not, it wins on cost.
      std::vector<RelativePose> from_fundamental;
      if (options.pose.start_from_fundamental) {
        from_fundamental.push_back(PoseFromFundamental(link.F, *camera, verified_from, verified_to));
      }
      pose = options.pose.use_all_matches
                 ? EstimateRelativePose(*camera, all_from, all_to, options.pose, from_fundamental)
                 : EstimateRelativePose(*camera, verified_from, verified_to, options.pose, from_fundamental);
    }
    if (pose.valid) {
      link.has_pose = true;
      link.R = pose.R;
      link.t = pose.t;
      link.pose_inliers = pose.num_inliers;
    }
  }
  link.parallax_without_rotation = link.has_pose;
  link.parallax = Median(Displacements(verified_from, verified_to, link.has_pose ? camera : nullptr,
                                       link.has_pose ? &link.R : nullptr));

  const HomographyCheck homography = CheckHomography(verified_from, verified_to, options.homography);
  if (homography.estimated) {
    link.homography_share = homography.share;
    link.planar = homography.explains;
  }
}

void AnalyzeLinks(VisualMap& map, const LinkAnalysisOptions& options, int threads) {
  const Camera* camera = map.input.camera ? &*map.input.camera : nullptr;
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    for (size_t i = next++; i < map.links.size(); i = next++) {
      try {
        AnalyzeLink(map.links[i], camera, options);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> workers;
  const int extra = std::min<int>(std::max(threads, 1), static_cast<int>(map.links.size())) - 1;
  for (int k = 0; k < extra; ++k) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace vmap
