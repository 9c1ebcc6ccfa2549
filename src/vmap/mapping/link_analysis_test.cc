// Link analysis: the cache that lets snapshots of a live run skip links analysed before.

#include "vmap/mapping/link_analysis.h"

#include <gtest/gtest.h>

#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

// A map with a camera (KITTI layout), so that links get poses: the costly part of the analysis.
const VisualMap& AnalysedMap() {
  static const VisualMap map = [] {
    testing::SyntheticOptions scene;
    scene.num_frames = 40;
    scene.step = 0.06;
    scene.yaw_per_frame = 0.01;
    const testing::ScopedTempDir tmp("link_analysis");
    testing::WriteKittiSequence(testing::RenderSyntheticSequence(scene), tmp.path() / "kitti");
    MapBuilderOptions options;
    options.key_images.tau = 0.7;
    options.show_progress = false;
    options.verifier.threshold = 1.0;
    const auto matcher = CreateOrbMatcher({});
    auto source = OpenFrameSource((tmp.path() / "kitti").string(), {});
    return BuildMap(*source, *matcher, options);
  }();
  return map;
}

// The map as Algorithm 1 leaves it, before any analysis (values no analysis gives, so a missed copy shows).
VisualMap Unanalysed() {
  VisualMap map = AnalysedMap();
  for (Link& link : map.links) {
    link.has_pose = false;
    link.R = cv::Matx33d::zeros();
    link.pose_inliers = -7;
    link.translation_sigma_deg = -7.0;
    link.translation_known = false;
    link.parallax = -7.0;
    link.homography_share = -7.0;
  }
  return map;
}

void ExpectSameAnalysis(const VisualMap& actual, const VisualMap& expected) {
  ASSERT_EQ(actual.links.size(), expected.links.size());
  for (size_t i = 0; i < actual.links.size(); ++i) {
    const Link& a = actual.links[i];
    const Link& e = expected.links[i];
    EXPECT_EQ(a.has_pose, e.has_pose) << i;
    EXPECT_EQ(a.R, e.R) << i;
    EXPECT_EQ(a.t, e.t) << i;
    EXPECT_EQ(a.pose_inliers, e.pose_inliers) << i;
    EXPECT_EQ(a.translation_sigma_deg, e.translation_sigma_deg) << i;
    EXPECT_EQ(a.translation_known, e.translation_known) << i;
    EXPECT_EQ(a.parallax, e.parallax) << i;
    EXPECT_EQ(a.parallax_without_rotation, e.parallax_without_rotation) << i;
    EXPECT_EQ(a.homography_share, e.homography_share) << i;
    EXPECT_EQ(a.planar, e.planar) << i;
  }
}

TEST(LinkAnalysisCache, ASecondCollectionReusesEveryUnchangedLink) {
  ASSERT_TRUE(AnalysedMap().input.camera);
  ASSERT_GE(AnalysedMap().links.size(), 3u);
  for (const Link& link : AnalysedMap().links) ASSERT_TRUE(link.has_pose);
  const LinkAnalysisOptions options;
  LinkAnalysisCache cache;
  VisualMap first = Unanalysed();
  AnalyzeLinks(first, options, 2, &cache);
  EXPECT_EQ(cache.hits(), 0);
  ExpectSameAnalysis(first, AnalysedMap());

  VisualMap second = Unanalysed();
  AnalyzeLinks(second, options, 2, &cache);
  EXPECT_EQ(cache.hits(), static_cast<long>(second.links.size()));
  ExpectSameAnalysis(second, AnalysedMap());
}

TEST(LinkAnalysisCache, AChangedLinkIsAnalysedAgain) {
  const LinkAnalysisOptions options;
  LinkAnalysisCache cache;
  VisualMap map = Unanalysed();
  AnalyzeLinks(map, options, 1, &cache);

  // The last link lost its last rejected match (a link verified again in full, or the last key of a live run).
  VisualMap changed = Unanalysed();
  Link& last = changed.links.back();
  ASSERT_GT(last.correspondences.size(), static_cast<size_t>(last.num_verified));
  last.correspondences.pop_back();
  --last.num_tentative;
  AnalyzeLinks(changed, options, 1, &cache);
  EXPECT_EQ(cache.hits(), static_cast<long>(changed.links.size()) - 1);
  VisualMap fresh = changed;
  AnalyzeLinks(fresh, options, 1);
  ExpectSameAnalysis(changed, fresh);
}

TEST(LinkAnalysisCache, KeepsOnlyTheLinksOfTheLastMap) {
  const LinkAnalysisOptions options;
  LinkAnalysisCache cache;
  VisualMap full = Unanalysed();
  AnalyzeLinks(full, options, 1, &cache);
  VisualMap shorter = Unanalysed();
  shorter.links.pop_back();
  AnalyzeLinks(shorter, options, 1, &cache);
  EXPECT_EQ(cache.hits(), static_cast<long>(shorter.links.size()));
  // The dropped link was forgotten: the full map's last link is analysed again.
  VisualMap again = Unanalysed();
  AnalyzeLinks(again, options, 1, &cache);
  EXPECT_EQ(cache.hits(), 2 * static_cast<long>(shorter.links.size()));
  ExpectSameAnalysis(again, AnalysedMap());
}

}  // namespace
}  // namespace vmap
