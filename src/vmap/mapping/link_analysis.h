#pragma once
// What a robot needs to know about a link besides S and F: the relative pose of its two key images (when
// the camera is known), how much parallax its matches have, and whether a homography explains them as well
// as F (then F and the pose are ill-posed). Computed from the link's stored matches after Algorithm 1 has
// chosen the key images, so it never changes which key images are chosen.

#include <cstdint>
#include <map>
#include <utility>

#include <nlohmann/json_fwd.hpp>

#include "vmap/geometry/camera.h"
#include "vmap/geometry/homography.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/map/visual_map.h"

namespace vmap {

struct LinkAnalysisOptions {
  PoseOptions pose;                // how the pose is estimated (docs/method.md, "The relative pose of a link")
  HomographyOptions homography;    // when a homography counts as explaining the matches
  TranslationOptions translation;  // when a link's translation direction is trusted (docs/link-poses.md)

  // As map.json records it: {"pose": ..., "homography": ..., "translation": ...} (geometry/relative_pose.h,
  // geometry/homography.h).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Fills link.has_pose/R/t/pose_inliers and how well t is known (with a camera), link.parallax and the
// homography test, from the
// link's correspondences (verified first) and F. A link without F gets none of them.
void AnalyzeLink(Link& link, const Camera* camera, const LinkAnalysisOptions& options);

// The analyses of one map's links, kept for when the same map is collected again as a run goes on (a snapshot
// every few seconds, `vmap build --snapshot-every`): a link whose key frames, F and correspondences are those
// of a link analysed before gets that analysis back instead of estimating it again. For one map (one tau),
// one camera and one LinkAnalysisOptions.
class LinkAnalysisCache {
 public:
  long hits() const { return hits_; }  // links that were not analysed again

 private:
  friend void AnalyzeLinks(VisualMap&, const LinkAnalysisOptions&, int, LinkAnalysisCache*);
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
void AnalyzeLinks(VisualMap& map, const LinkAnalysisOptions& options, int threads = 1,
                  LinkAnalysisCache* cache = nullptr);

}  // namespace vmap
