#include "vmap/mapping/link_analysis.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/core/json_fields.h"

namespace vmap {

void LinkAnalysisOptions::Check() const {
  CheckField("pose", pose);
  CheckField("homography", homography);
  CheckField("translation", translation);
}

void AnalyzeLink(Link& link, const Camera* camera, const LinkAnalysisOptions& options) {
  link.has_pose = false;
  link.R = cv::Matx33d::eye();
  link.t = cv::Vec3d();
  link.pose_inliers = 0;
  link.translation_sigma_deg = -1.0;
  link.translation_rival_cost_gap = -1.0;
  link.translation_known = false;
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
    std::vector<PoseMinimum> minima;
    const std::vector<cv::Point2f>& pose_from = options.pose.use_all_matches ? all_from : verified_from;
    const std::vector<cv::Point2f>& pose_to = options.pose.use_all_matches ? all_to : verified_to;
    const NormalizedMatches pose_matches(*camera, pose_from, pose_to);  // undistorted once for every step below
    if (options.pose.method == PoseMethod::kFromFundamental) {
      pose = PoseFromFundamental(link.F, *camera, verified_from, verified_to);
    } else {
      // The pose of F is one more start: where it is right and USAC's are not, it wins on cost.
      std::vector<RelativePose> from_fundamental;
      if (options.pose.start_from_fundamental) {
        from_fundamental.push_back(PoseFromFundamental(link.F, *camera, verified_from, verified_to));
      }
      pose = EstimateRelativePose(pose_matches, options.pose, from_fundamental, &minima);
    }
    if (pose.valid && options.pose.method == PoseMethod::kEssential) {
      // Probes at twice the rival angle: one that stays there is a rival, one that returns is not. One that
      // ends lower than every start found a better pose by the estimate's own cost: it becomes the pose.
      const std::vector<PoseMinimum> probes =
          ProbeTranslation(pose, pose_matches, options.pose, 2.0 * options.translation.rival_angle_deg);
      minima.insert(minima.end(), probes.begin(), probes.end());
      pose = std::min_element(minima.begin(), minima.end(), [](const PoseMinimum& a, const PoseMinimum& b) {
               return a.cost < b.cost;
             })->pose;
      const double gap = RivalCostGap(minima, options.translation.rival_angle_deg);
      if (std::isfinite(gap)) link.translation_rival_cost_gap = gap;
    }
    if (pose.valid) {
      link.has_pose = true;
      link.R = pose.R;
      link.t = pose.t;
      link.pose_inliers = pose.num_inliers;
      link.translation_sigma_deg = TranslationSigmaDeg(
          pose, pose_matches, options.pose.refine_inlier_factor * options.pose.threshold, options.pose.threshold);
    }
  }
  link.parallax_without_rotation = link.has_pose;
  link.parallax = Median(
      Displacements(verified_from, verified_to, link.has_pose ? camera : nullptr, link.has_pose ? &link.R : nullptr));
  const double rival_cost_gap =
      link.translation_rival_cost_gap >= 0 ? link.translation_rival_cost_gap : std::numeric_limits<double>::infinity();
  link.translation_known =
      link.has_pose && TranslationKnown(link.translation_sigma_deg, link.parallax, rival_cost_gap, options.translation);

  const HomographyCheck homography = CheckHomography(verified_from, verified_to, options.homography);
  if (homography.estimated) {
    link.homography_share = homography.share;
    link.planar = homography.explains;
  }
}

namespace {

// FNV-1a over the bytes of what AnalyzeLink reads.
class Fingerprint {
 public:
  template <typename T>
  void Add(const T& value) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    for (size_t i = 0; i < sizeof(T); ++i) hash_ = (hash_ ^ bytes[i]) * 1099511628211ull;
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 14695981039346656037ull;
};

uint64_t FingerprintOf(const Link& link) {
  Fingerprint fingerprint;
  fingerprint.Add(link.has_fundamental);
  fingerprint.Add(link.num_verified);
  fingerprint.Add(link.num_tentative);
  for (int i = 0; i < 9; ++i) fingerprint.Add(link.F.val[i]);
  fingerprint.Add(link.correspondences.size());
  for (const Correspondence& c : link.correspondences) {
    fingerprint.Add(c.p0.x);
    fingerprint.Add(c.p0.y);
    fingerprint.Add(c.p1.x);
    fingerprint.Add(c.p1.y);
  }
  return fingerprint.value();
}

void CopyAnalysis(const Link& from, Link& to) {
  to.has_pose = from.has_pose;
  to.R = from.R;
  to.t = from.t;
  to.pose_inliers = from.pose_inliers;
  to.translation_sigma_deg = from.translation_sigma_deg;
  to.translation_rival_cost_gap = from.translation_rival_cost_gap;
  to.translation_known = from.translation_known;
  to.parallax = from.parallax;
  to.parallax_without_rotation = from.parallax_without_rotation;
  to.homography_share = from.homography_share;
  to.planar = from.planar;
}

}  // namespace

void AnalyzeLinks(VisualMap& map, const LinkAnalysisOptions& options, int threads, LinkAnalysisCache* cache) {
  const Camera* camera = map.input.camera ? &*map.input.camera : nullptr;
  const auto frames_of = [&map](const Link& link) {
    return std::make_pair(map.key_images.at(link.from_key).frame_index, map.key_images.at(link.to_key).frame_index);
  };
  std::vector<size_t> todo;
  std::vector<uint64_t> fingerprints(map.links.size(), 0);
  for (size_t i = 0; i < map.links.size(); ++i) {
    if (cache) {
      fingerprints[i] = FingerprintOf(map.links[i]);
      const auto it = cache->entries_.find(frames_of(map.links[i]));
      if (it != cache->entries_.end() && it->second.fingerprint == fingerprints[i]) {
        CopyAnalysis(it->second.analysed, map.links[i]);
        ++cache->hits_;
        continue;
      }
    }
    todo.push_back(i);
  }

  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    for (size_t k = next++; k < todo.size(); k = next++) {
      try {
        AnalyzeLink(map.links[todo[k]], camera, options);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> workers;
  const int extra = std::min<int>(std::max(threads, 1), static_cast<int>(todo.size())) - 1;
  for (int k = 0; k < extra; ++k) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();
  if (error) std::rethrow_exception(error);

  if (!cache) return;
  // Only this map's links stay: a live run's last link changes at every snapshot.
  std::map<std::pair<int, int>, LinkAnalysisCache::Entry> kept;
  for (size_t i = 0; i < map.links.size(); ++i) {
    LinkAnalysisCache::Entry& entry = kept[frames_of(map.links[i])];
    entry.fingerprint = fingerprints[i];
    CopyAnalysis(map.links[i], entry.analysed);
  }
  cache->entries_ = std::move(kept);
}

void LinkAnalysisOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.VisitNested("pose", pose);
  visitor.VisitNested("homography", homography);
  visitor.VisitNested("translation", translation);
}

}  // namespace vmap
