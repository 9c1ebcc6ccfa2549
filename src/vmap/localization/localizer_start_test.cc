// The start of a run (LocalizerOptions::start_key): a teach-and-repeat robot starts where the teach run started, so
// the tracker starts at that key image and the belief leans there; a soft prior, which the frames' evidence overrides
// when the run starts elsewhere.

#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "vmap/localization/localization_map.h"
#include "vmap/localization/localizer.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/localizer_test_util.h"
#include "vmap/testing/option_error.h"

namespace vmap {
namespace {

using ::vmap::testing::Brackets;
using ::vmap::testing::DenseDriveMap;

// Drive frame `source_index` (or a blank image when -1) localized as the `index`-th frame of a stream.
LocalizationResult LocalizeDrive(Localizer& localizer, int source_index, int index) {
  const cv::Mat image = source_index >= 0
                            ? ::vmap::testing::SidewaysDrive().frames[source_index]
                            : cv::Mat(::vmap::testing::SidewaysDrive().frames[0].size(), CV_8UC3, cv::Scalar::all(128));
  ::vmap::testing::MemorySource source({image}, {std::max(source_index, 0)});
  Frame frame = *source.Next();
  frame.index = index;
  const auto features = DenseDriveMap().matcher->Extract(frame.gray);
  return localizer.Localize(frame, *features);
}

TEST(Localizer, AStartKeyStartsTheTrackerThere) {
  const LocalizationMap& m = DenseDriveMap();
  ASSERT_GE(m.map.key_images.size(), 8u);
  LocalizerOptions anywhere = MapLocalizerOptions(m);
  ASSERT_EQ(anywhere.start_key, -1) << "anywhere by default";
  LocalizerOptions at_start = anywhere;
  at_start.start_key = 0;
  Localizer started(m.map, m.keys, *m.matcher, at_start);
  EXPECT_TRUE(started.has_estimate());
  EXPECT_EQ(started.LikelyKeys(), (std::vector<int>{0, 1}));
  Localizer elsewhere(m.map, m.keys, *m.matcher, anywhere);
  EXPECT_FALSE(elsewhere.has_estimate());
  // The first frame is tracked from the start key image, not relocalized over the whole route.
  const LocalizationResult first = LocalizeDrive(started, 1, 0);
  EXPECT_EQ(first.status, LocalizationStatus::kTracking);
  EXPECT_TRUE(Brackets(m.map, 1, first.key)) << first.key;
  EXPECT_EQ(LocalizeDrive(elsewhere, 1, 0).status, LocalizationStatus::kRelocalized);
  // Reset starts again there.
  LocalizeDrive(started, 21, 1);
  started.Reset();
  EXPECT_EQ(started.LikelyKeys(), (std::vector<int>{0, 1}));
}

TEST(Localizer, AFrameNothingVerifiesAtTheStartIsAtTheStartKeyImage) {
  const LocalizationMap& m = DenseDriveMap();
  LocalizerOptions options = MapLocalizerOptions(m);
  options.start_key = 2;
  Localizer started(m.map, m.keys, *m.matcher, options);
  const LocalizationResult blank = LocalizeDrive(started, -1, 0);
  EXPECT_EQ(blank.status, LocalizationStatus::kLost);
  EXPECT_EQ(blank.key, 2) << "the best guess: where the run starts";
  Localizer anywhere(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  EXPECT_EQ(LocalizeDrive(anywhere, -1, 0).key, -1);
}

// A soft prior: a run that starts mid-route with the start key image at the route's start is where it is from its
// second frame on, as a run without a start key image is.
TEST(Localizer, ARunStartedElsewhereIsNotTrappedAtTheStartKey) {
  const LocalizationMap& m = DenseDriveMap();
  LocalizerOptions at_start = MapLocalizerOptions(m);
  at_start.start_key = 0;
  Localizer started(m.map, m.keys, *m.matcher, at_start);
  Localizer anywhere(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  int index = 0, steered = 0;
  for (int source_index = 41; source_index < 60; source_index += 2, ++index) {
    const LocalizationResult r = LocalizeDrive(started, source_index, index);
    const LocalizationResult a = LocalizeDrive(anywhere, source_index, index);
    if (index == 0) continue;  // the first frame may doubt a far place (uncertain), the second confirms it
    EXPECT_TRUE(Brackets(m.map, source_index, r.key)) << source_index << " at key " << r.key;
    EXPECT_TRUE(Brackets(m.map, source_index, a.key)) << source_index << " at key " << a.key;
    steered += IsPlaced(r.status);
  }
  EXPECT_EQ(steered, index - 1);
}

TEST(Localizer, TheStartIsChecked) {
  const LocalizationMap& m = DenseDriveMap();
  auto path = [](auto change) {
    return testing::OptionErrorPath([&] {
      LocalizerOptions options;
      change(options);
      options.Check();
    });
  };
  EXPECT_EQ(path([](LocalizerOptions& o) { o.start_key = -2; }), "start_key");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.start_mass = 1.0; }), "start_mass");
  LocalizerOptions off_route = MapLocalizerOptions(m);
  off_route.route = {0, 1, 2};
  off_route.start_key = 3;
  EXPECT_THROW(Localizer(m.map, m.keys, *m.matcher, off_route), InputError);
  off_route.start_key = static_cast<int>(m.map.key_images.size());
  EXPECT_THROW(Localizer(m.map, m.keys, *m.matcher, off_route), InputError);
}

}  // namespace
}  // namespace vmap
