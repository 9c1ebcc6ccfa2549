#pragma once
// What a robot needs to know about a link besides S and F: the relative pose of its two key images (when
// the camera is known), how much parallax its matches have, and whether a homography explains them as well
// as F (then F and the pose are ill-posed). Computed from the link's stored matches after Algorithm 1 has
// chosen the key images, so it never changes which key images are chosen; the pose is then cross-checked
// against a second estimate from denser features of the two key images (CrossCheckLinkPose).

#include <cstdint>
#include <functional>
#include <map>
#include <utility>

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "vmap/geometry/camera.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/homography.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/geometry/translation_evidence.h"
#include "vmap/map/visual_map.h"

namespace vmap {

struct LinkAnalysisOptions {
  PoseOptions pose;                // how the pose is estimated (docs/method.md, "The relative pose of a link")
  HomographyOptions homography;    // when a homography counts as explaining the matches
  TranslationOptions translation;  // when a link's translation direction is trusted (docs/link-poses.md)
  // A second estimate of each link's pose, from ORB features of its two key images extracted anew, this many per
  // image (denser than a map's own ORB features), matched and verified again (CrossCheckLinkPose). The link keeps
  // the pose of the estimate with more tentative matches, and its translation is known only where both
  // estimates know it and agree within translation.rival_angle_deg. 0: the link's own matches only. 2000:
  // the only count of 1000, 2000 and 3000 with >= 95 % usable links on redkitchen 0-499 (docs/link-poses.md).
  int pose_check_features = 2000;

  // As map.json records it: {"pose": ..., "homography": ..., "translation": ..., "pose_check_features": ...}
  // (geometry/relative_pose.h, geometry/homography.h, geometry/translation_evidence.h).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Fills link.has_pose/R/t/pose_inliers and how well t is known (with a camera), link.parallax and the
// homography test, from the link's correspondences (verified first) and F. A link without F gets none of them.
void AnalyzeLink(Link& link, const Camera* camera, const LinkAnalysisOptions& options);

// Checks `link`'s pose (AnalyzeLink's) against `denser`, the same two key images analysed from other, denser
// matches (AnalyzeLink too). When both have a pose: the link takes denser's pose, sigma and rival gap if denser
// has more tentative matches (and the parallax of its own verified matches under that rotation), and its
// translation is known only when both estimates' are and their translations are at most
// `translation.rival_angle_deg` apart. Two estimates from different features that disagree show a translation
// the matches do not determine, whatever each one's sigma says. Without both poses the link stays as it is.
void CrossCheckLinkPose(Link& link, const Link& denser, const Camera& camera, const TranslationOptions& translation);

// What the pose cross-check (LinkAnalysisOptions::pose_check_features) reads besides the map.
struct PoseCheckInputs {
  // A key image's pixels, 8-bit grey: e.g. ReadKeyImage from the map directory being written.
  std::function<cv::Mat(const KeyImage&)> read_key_image;
  VerifierOptions verifier;  // the map's
};

// The analyses of one map's links, kept for when the same map is collected again as a run goes on (a snapshot
// every few seconds, `vmap build --snapshot-every`): a link whose key frames, F and correspondences are those
// of a link analysed before gets that analysis back instead of estimating it again. For one map (one tau),
// one camera and one LinkAnalysisOptions.
class LinkAnalysisCache {
 public:
  long hits() const { return hits_; }  // links that were not analysed again

 private:
  friend void AnalyzeLinks(VisualMap&, const LinkAnalysisOptions&, int, LinkAnalysisCache*, const PoseCheckInputs*,
                           const std::function<void()>&);
  struct Entry {
    uint64_t fingerprint = 0;  // of what the analysis reads: the counts, F and the correspondences
    Link analysed;             // only the fields AnalyzeLink fills are used (no correspondences kept)
  };
  std::map<std::pair<int, int>, Entry> entries_;  // by the link's (from, to) frame index
  long hits_ = 0;
};

// AnalyzeLink for every link, with the map's camera (map.input.camera) when it has one, on `threads` threads
// (links are independent: the result does not depend on the number of threads). With `cache`, links analysed
// by an earlier call are not analysed again, and the cache keeps only this map's links (memory stays flat).
// With `inputs`, a camera and options.pose_check_features > 0, each posed link is also cross-checked
// against the pose of denser features of its key images (CrossCheckLinkPose). `link_done` (may be empty) is called
// once per link as it is done, one call at a time: a progress line's.
void AnalyzeLinks(VisualMap& map, const LinkAnalysisOptions& options, int threads = 1,
                  LinkAnalysisCache* cache = nullptr, const PoseCheckInputs* inputs = nullptr,
                  const std::function<void()>& link_done = {});

}  // namespace vmap
