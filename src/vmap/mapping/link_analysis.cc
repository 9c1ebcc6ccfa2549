#include "vmap/mapping/link_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/core/json_fields.h"
#include "vmap/core/numeric.h"
#include "vmap/core/parallel_for.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/key_image_selector.h"

namespace vmap {

void LinkAnalysisOptions::Check() const {
  CheckField("pose", pose);
  CheckField("homography", homography);
  CheckField("translation", translation);
  if (pose_check_features < 0 || pose_check_features > 100000) {
    throw OptionError("pose_check_features", "must be 0 (no cross-check) to 100000 ORB features per key image");
  }
}

namespace {

// AnalyzeLink; without `test_homography` the homography fields are left unset (a pose cross-check's denser
// estimate, whose homography nobody reads).
void Analyze(Link& link, const Camera* camera, const LinkAnalysisOptions& options, bool test_homography) {
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
      const double rival_cost_gap = link.translation_rival_cost_gap >= 0 ? link.translation_rival_cost_gap
                                                                         : std::numeric_limits<double>::infinity();
      const TranslationEvidence evidence =
          AssessTranslation(pose, pose_matches, NormalizedMatches(*camera, verified_from, verified_to), options.pose,
                            options.translation, rival_cost_gap);
      link.translation_sigma_deg = evidence.sigma_deg;
      link.parallax = evidence.parallax_px;
      link.translation_known = evidence.known;
    }
  }
  // Without a pose, the plain displacement.
  link.parallax_without_rotation = link.has_pose;
  if (!link.has_pose) link.parallax = Median(Displacements(verified_from, verified_to));

  if (!test_homography) return;
  // In an order of their own, not the estimator's: the verified matches come in the order of the estimate that
  // decided the link, which depends on the thresholds it settled, and the same link of `vmap build` and of a sweep's
  // map had another share (kitti07: 6 of 47 links, 0.455 and 0.401).
  std::vector<size_t> order(verified_from.size());
  std::iota(order.begin(), order.end(), size_t{0});
  const auto key = [&](size_t i) {
    return std::make_tuple(verified_from[i].x, verified_from[i].y, verified_to[i].x, verified_to[i].y);
  };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
  std::vector<cv::Point2f> sorted_from, sorted_to;
  for (const size_t i : order) {
    sorted_from.push_back(verified_from[i]);
    sorted_to.push_back(verified_to[i]);
  }
  const HomographyCheck homography = CheckHomography(sorted_from, sorted_to, options.homography);
  if (homography.estimated) {
    link.homography_share = homography.share;
    link.planar = homography.explains;
  }
}

}  // namespace

void AnalyzeLink(Link& link, const Camera* camera, const LinkAnalysisOptions& options) {
  Analyze(link, camera, options, /*test_homography=*/true);
}

void CrossCheckLinkPose(Link& link, const Link& denser, const Camera& camera, const TranslationOptions& translation) {
  if (!link.has_pose || !denser.has_pose) return;
  const bool agree = AngleBetweenDeg(link.t, denser.t) <= translation.rival_angle_deg;
  const bool known = link.translation_known && denser.translation_known && agree;
  if (denser.num_tentative > link.num_tentative) {
    link.R = denser.R;
    link.t = denser.t;
    link.pose_inliers = denser.pose_inliers;
    link.translation_sigma_deg = denser.translation_sigma_deg;
    link.translation_rival_cost_gap = denser.translation_rival_cost_gap;
    std::vector<cv::Point2f> from, to;
    SplitCorrespondences(link.correspondences, &from, &to, link.num_verified);
    link.parallax = RotationCompensatedParallax(NormalizedMatches(camera, from, to), link.R);
  }
  link.translation_known = known;
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

void AnalyzeLinks(VisualMap& map, const LinkAnalysisOptions& options, int threads, LinkAnalysisCache* cache,
                  const PoseCheckInputs* inputs, const std::function<void()>& link_done) {
  std::mutex link_done_mutex;
  const auto done = [&] {
    if (!link_done) return;
    std::lock_guard<std::mutex> lock(link_done_mutex);
    link_done();
  };
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
        done();
        continue;
      }
    }
    todo.push_back(i);
  }

  const bool cross_check = camera && inputs && inputs->read_key_image && options.pose_check_features > 0;
  std::unique_ptr<Matcher> denser_matcher;
  if (cross_check) {
    OrbMatcherOptions orb;
    orb.num_features = options.pose_check_features;
    denser_matcher = CreateOrbMatcher(orb);
  }
  // In chunks of links, so that only a chunk's key images' denser features are held at once; each key image's
  // features are extracted once per chunk (a key image is in two links).
  constexpr size_t kChunkLinks = 256;
  for (size_t begin = 0; begin < todo.size(); begin += kChunkLinks) {
    const size_t end = std::min(todo.size(), begin + kChunkLinks);
    std::map<int, std::shared_ptr<const ImageFeatures>> features;  // by key-image index
    if (cross_check) {
      for (size_t k = begin; k < end; ++k) {
        features[map.links[todo[k]].from_key];
        features[map.links[todo[k]].to_key];
      }
      std::vector<std::pair<const int, std::shared_ptr<const ImageFeatures>>*> slots;
      for (auto& slot : features) slots.push_back(&slot);
      ParallelFor(slots.size(), threads, [&](size_t i) {
        slots[i]->second = denser_matcher->Extract(inputs->read_key_image(map.key_images.at(slots[i]->first)));
      });
    }
    ParallelFor(end - begin, threads, [&](size_t k) {
      Link& link = map.links[todo[begin + k]];
      AnalyzeLink(link, camera, options);
      if (cross_check && link.has_pose) {
        Link denser = MakeLink(ComparePair(*denser_matcher, *features.at(link.from_key), *features.at(link.to_key),
                                           inputs->verifier, SimilarityMode::kInlierRatio),
                               link.from_key, link.to_key, link.below_tau);
        Analyze(denser, camera, options, /*test_homography=*/false);
        CrossCheckLinkPose(link, denser, *camera, options.translation);
      }
      done();
    });
  }

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
  visitor.Section("Links: the relative pose of each link (with --camera)");
  visitor.VisitNested("pose", pose);
  visitor.VisitNested("homography", homography);
  visitor.VisitNested("translation", translation);
  visitor.Visit(OptionField{"pose_check_features", "--pose-check-features",
                            "ORB features per key image for a second estimate of each link's pose: its translation is "
                            "known only where both estimates agree (0: the link's own matches only)"}
                    .Within(0, 100000)
                    .Meaning("0: the link's own matches only"),
                pose_check_features);
}

}  // namespace vmap
