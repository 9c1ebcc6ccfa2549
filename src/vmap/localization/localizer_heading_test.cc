// The heading and the pose a comparison gives a controller, against a one-key-image map of the sideways drive.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/features/orb_matcher.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localizer.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/localizer_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

using ::vmap::testing::MakeFrame;
using ::vmap::testing::SidewaysDrive;

TEST(Localizer, HeadingIsTheHorizontalShiftOfTheSceneInPixels) {
  // A map of one key image: the frame is at the route's end and the heading refers to that key image.
  ::vmap::testing::ScopedTempDir directory;
  const auto matcher = CreateOrbMatcher({});
  MapBuilderOptions build;
  build.show_progress = false;
  const cv::Mat key_image = SidewaysDrive().frames[30];
  ::vmap::testing::MemorySource source(std::vector<cv::Mat>{key_image});
  ::vmap::testing::BuildMapDirectory(source, *matcher, build, directory.path() / "map");
  const LocalizationMap m = OpenLocalizationMap(directory.path() / "map", {});
  ASSERT_EQ(m.map.key_images.size(), 1u);
  for (double shift : {-14.0, 9.0}) {
    Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
    cv::Mat shifted;
    const cv::Matx23d translation(1, 0, shift, 0, 1, 0);
    cv::warpAffine(key_image, shifted, translation, key_image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    const Frame frame = MakeFrame(shifted, 0, 0);
    const LocalizationResult r = localizer.Localize(frame, *m.matcher->Extract(frame.gray));
    ASSERT_EQ(r.status, LocalizationStatus::kRelocalized);
    EXPECT_EQ(r.key, 0);
    EXPECT_EQ(r.next_key, -1);
    EXPECT_NEAR(r.heading_px, shift, 1.0) << "the scene moved " << shift << " px to the right";
    // At the route's end the target is `key` itself: both headings are the one estimate.
    EXPECT_EQ(r.heading_key_px, r.heading_px);
    EXPECT_TRUE(r.to_key.heading.valid());
    EXPECT_GT(r.to_key.heading.confidence, 0.5) << "a pure shift: most matches agree";
  }
}

// With the map's camera: the heading as a bearing in degrees, and the pose of the key image relative to the
// frame, against the drive's true poses.
TEST(Localizer, WithACameraTheHeadingIsInDegreesAndThePoseIsTheTrueOne) {
  ::vmap::testing::ScopedTempDir directory;
  const auto matcher = CreateOrbMatcher({});
  MapBuilderOptions build;
  build.show_progress = false;
  const int key_index = 30, frame_index = 22;
  const cv::Mat key_image = SidewaysDrive().frames[key_index];
  ::vmap::testing::MemorySource source(std::vector<cv::Mat>{key_image});
  ::vmap::testing::BuildMapDirectory(source, *matcher, build, directory.path() / "map");
  const LocalizationMap m = OpenLocalizationMap(directory.path() / "map", {});
  const cv::Matx33d K = SidewaysDrive().K;
  LocalizerOptions options = MapLocalizerOptions(m);
  options.camera = Camera::Make(K(0, 0), K(1, 1), K(0, 2), K(1, 2));

  // A pure shift of the image by s pixels is a turn of about atan(s / f) near the centre.
  const double shift = 12.0;
  cv::Mat shifted;
  cv::warpAffine(key_image, shifted, cv::Matx23d(1, 0, shift, 0, 1, 0), key_image.size(), cv::INTER_LINEAR,
                 cv::BORDER_REFLECT);
  {
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    const Frame frame = MakeFrame(shifted, 0, 0);
    const LocalizationResult r = localizer.Localize(frame, *m.matcher->Extract(frame.gray));
    ASSERT_EQ(r.status, LocalizationStatus::kRelocalized);
    EXPECT_NEAR(r.heading_deg, std::atan(shift / K(0, 0)) * 180.0 / M_PI, 0.2);
    EXPECT_GT(r.heading_deg * r.heading_px, 0.0) << "degrees and pixels agree in sign";
  }
  // A frame of the drive 8 frames before the key image (1.4 degrees of yaw): R and t against the true motion
  // from it to the key image.
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  const Frame frame = MakeFrame(SidewaysDrive().frames[frame_index], 0, frame_index);
  const LocalizationResult r = localizer.Localize(frame, *m.matcher->Extract(frame.gray));
  ASSERT_EQ(r.status, LocalizationStatus::kRelocalized);
  const RelativePose& pose = r.to_key.pose;
  ASSERT_TRUE(pose.valid);
  const auto& from = SidewaysDrive().poses[frame_index];
  const auto& to = SidewaysDrive().poses[key_index];
  const cv::Matx33d true_R = to.R * from.R.t();
  const cv::Vec3d true_t = to.t - true_R * from.t;
  const cv::Matx33d dR = pose.R * true_R.t();
  const double rotation_error_deg = std::acos(std::clamp((cv::trace(dR) - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
  const double cosine = pose.t.dot(true_t) / cv::norm(true_t);
  // The pose comes from F (cheap enough for every frame), which the planes of this scene leave less certain
  // than the map links' refined estimate: about 0.6 degrees off here. The inverse motion would be 2.75
  // degrees off with t reversed.
  EXPECT_LT(rotation_error_deg, 1.0);
  EXPECT_GT(cosine, std::cos(15.0 * M_PI / 180.0)) << "translation direction within 15 degrees";
  ASSERT_TRUE(std::isfinite(r.to_key.translation_sigma_deg));
  if (r.to_key.translation_sigma_deg > options.translation.max_sigma_deg) {
    EXPECT_FALSE(r.translation_known);
  }
  EXPECT_EQ(LocalizationGuidance(r),
            r.translation_known ? "heading and translation" : "heading only: translation unknown");

  // Without the camera: no degrees, no pose.
  Localizer pixels_only(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  const LocalizationResult p = pixels_only.Localize(frame, *m.matcher->Extract(frame.gray));
  EXPECT_TRUE(std::isnan(p.heading_deg));
  EXPECT_FALSE(p.to_key.pose.valid);
  EXPECT_FALSE(p.translation_known);
  EXPECT_EQ(LocalizationGuidance(p), "heading only: no pose");

  // A frame of another shape, stretched to the map's size: the map's camera does not describe it. One of the map's
  // shape at twice the size: it does.
  const cv::Size teach = m.map.input.native_size;
  ASSERT_FALSE(teach.empty());
  Frame stretched = frame, scaled = frame;
  stretched.native_size = cv::Size(teach.width, teach.width);
  scaled.native_size = cv::Size(2 * teach.width, 2 * teach.height);
  Localizer of_another_shape(m.map, m.keys, *m.matcher, options);
  const LocalizationResult s = of_another_shape.Localize(stretched, *m.matcher->Extract(frame.gray));
  EXPECT_EQ(s.status, r.status);
  EXPECT_EQ(s.heading_px, r.heading_px);
  EXPECT_TRUE(std::isnan(s.heading_deg));
  EXPECT_TRUE(std::isnan(s.heading_key_deg));
  EXPECT_FALSE(s.to_key.pose.valid);
  EXPECT_FALSE(s.translation_known);
  EXPECT_EQ(LocalizationGuidance(s), "heading only: no pose");
  Localizer of_the_same_shape(m.map, m.keys, *m.matcher, options);
  const LocalizationResult t = of_the_same_shape.Localize(scaled, *m.matcher->Extract(frame.gray));
  EXPECT_EQ(t.heading_deg, r.heading_deg);
  EXPECT_TRUE(t.to_key.pose.valid);
}

}  // namespace
}  // namespace vmap
