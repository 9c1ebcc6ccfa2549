// Link analysis: the cache that lets snapshots of a live run skip links analysed before.

#include "vmap/mapping/link_analysis.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/core/numeric.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

// A drive with a camera (KITTI layout in `directory`), so that links get poses: the costly part of the analysis.
void WriteDrive(const std::filesystem::path& directory) {
  testing::SyntheticOptions scene;
  scene.num_frames = 40;
  scene.step = 0.06;
  scene.yaw_per_frame = 0.01;
  testing::WriteKittiSequence(testing::RenderSyntheticSequence(scene), directory);
}

MapBuilderOptions DriveBuildOptions() {
  MapBuilderOptions options;
  options.key_images.tau = 0.7;
  options.show_progress = false;
  options.verifier.threshold = 1.0;
  return options;
}

// The drive's map, built in memory: the links' own estimates only (no key-image files to cross-check with).
const VisualMap& AnalysedMap() {
  static const VisualMap map = [] {
    const testing::ScopedTempDir tmp("link_analysis");
    WriteDrive(tmp.path() / "kitti");
    auto source = OpenFrameSource((tmp.path() / "kitti").string(), {});
    return BuildMap(*source, *CreateOrbMatcher({}), DriveBuildOptions());
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

  // Each link is said done once, whether analysed or reused (a progress line counts them).
  VisualMap second = Unanalysed();
  long done = 0;
  AnalyzeLinks(second, options, 2, &cache, nullptr, [&] { ++done; });
  EXPECT_EQ(cache.hits(), static_cast<long>(second.links.size()));
  EXPECT_EQ(done, static_cast<long>(second.links.size()));
  ExpectSameAnalysis(second, AnalysedMap());
  VisualMap third = Unanalysed();
  done = 0;
  AnalyzeLinks(third, options, 2, nullptr, nullptr, [&] { ++done; });
  EXPECT_EQ(done, static_cast<long>(third.links.size()));
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

// A rotation of `degrees` about the camera's y axis (a turn of the robot).
cv::Matx33d Yaw(double degrees) {
  const double a = degrees * M_PI / 180.0;
  return cv::Matx33d(std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a));
}

TEST(CrossCheckLinkPose, TheTranslationIsKnownOnlyWhereBothEstimatesKnowItAndAgree) {
  const VisualMap& map = AnalysedMap();
  const Camera& camera = *map.input.camera;
  const TranslationOptions translation;  // rival angle 15 degrees
  const auto known =
      std::find_if(map.links.begin(), map.links.end(), [](const Link& l) { return l.translation_known; });
  ASSERT_NE(known, map.links.end()) << "a link whose translation is known";
  const Link own = *known;
  Link denser = own;
  denser.num_tentative = 4 * own.num_tentative;
  denser.R = own.R * Yaw(0.5);
  denser.pose_inliers = 3 * own.num_tentative;
  denser.translation_sigma_deg = 0.25;

  // 10 degrees apart: the same direction. The link takes the denser pose, and the parallax of its own verified
  // matches under that rotation.
  denser.t = Yaw(10.0) * own.t;
  Link link = own;
  CrossCheckLinkPose(link, denser, camera, translation);
  EXPECT_TRUE(link.translation_known);
  EXPECT_EQ(link.R, denser.R);
  EXPECT_EQ(link.t, denser.t);
  EXPECT_EQ(link.pose_inliers, denser.pose_inliers);
  EXPECT_EQ(link.translation_sigma_deg, 0.25);
  std::vector<cv::Point2f> from, to;
  SplitCorrespondences(own.correspondences, &from, &to, own.num_verified);
  EXPECT_EQ(link.parallax, Median(Displacements(from, to, &camera, &denser.R)));
  EXPECT_NE(link.parallax, own.parallax) << "the rotation changed: so does what it leaves of the displacements";

  // 20 degrees apart: two estimates that disagree; the pose is still the denser one.
  denser.t = Yaw(20.0) * own.t;
  link = own;
  CrossCheckLinkPose(link, denser, camera, translation);
  EXPECT_FALSE(link.translation_known);
  EXPECT_EQ(link.t, denser.t);

  // Agreeing, but the denser estimate does not know its translation.
  denser.t = own.t;
  denser.translation_known = false;
  link = own;
  CrossCheckLinkPose(link, denser, camera, translation);
  EXPECT_FALSE(link.translation_known);

  // The link's own estimate has more matches: it keeps its pose; the flag still needs both.
  denser.translation_known = true;
  denser.num_tentative = own.num_tentative / 2;
  denser.t = Yaw(30.0) * own.t;
  link = own;
  CrossCheckLinkPose(link, denser, camera, translation);
  EXPECT_EQ(link.t, own.t);
  EXPECT_EQ(link.R, own.R);
  EXPECT_FALSE(link.translation_known);

  // No denser pose: nothing to check against, the link stays as it was.
  denser.has_pose = false;
  link = own;
  CrossCheckLinkPose(link, denser, camera, translation);
  EXPECT_TRUE(link.translation_known);
  EXPECT_EQ(link.t, own.t);
  EXPECT_EQ(link.parallax, own.parallax);
}

// Built into a directory, the links are cross-checked with the key images read back from it: their poses come
// from the denser matches (more inliers than the link's own matches hold); with pose_check_features 0 they
// come from the link's own matches. The same input gives the same poses.
TEST(CrossCheckLinkPose, AMapBuiltIntoADirectoryIsCrossChecked) {
  const testing::ScopedTempDir tmp("cross_check");
  WriteDrive(tmp.path() / "kitti");
  const auto matcher = CreateOrbMatcher({});
  auto build = [&](int pose_check_features, const std::string& name) {
    MapBuilderOptions options = DriveBuildOptions();
    options.link_analysis.pose_check_features = pose_check_features;
    auto source = OpenFrameSource((tmp.path() / "kitti").string(), {});
    std::filesystem::create_directories(tmp.path() / name);
    return BuildMap(*source, *matcher, options, tmp.path() / name);
  };
  const VisualMap checked = build(2000, "checked");
  const VisualMap again = build(2000, "again");
  const VisualMap own = build(0, "own");
  ASSERT_EQ(checked.links.size(), own.links.size());
  ASSERT_GE(checked.links.size(), 3u);
  int denser_poses = 0;
  for (size_t i = 0; i < checked.links.size(); ++i) {
    ASSERT_TRUE(checked.links[i].has_pose);
    EXPECT_LE(own.links[i].pose_inliers, own.links[i].num_tentative) << i;
    denser_poses += checked.links[i].pose_inliers > checked.links[i].num_tentative;
    EXPECT_EQ(checked.links[i].R, again.links[i].R) << i;
    EXPECT_EQ(checked.links[i].t, again.links[i].t) << i;
    EXPECT_EQ(checked.links[i].translation_known, again.links[i].translation_known) << i;
  }
  EXPECT_EQ(denser_poses, static_cast<int>(checked.links.size()));
}

TEST(CrossCheckLinkPose, OptionsAreChecked) {
  LinkAnalysisOptions options;
  options.pose_check_features = -1;
  EXPECT_THROW(options.Check(), OptionError);
  options.pose_check_features = 0;
  EXPECT_NO_THROW(options.Check());
}

}  // namespace
}  // namespace vmap
