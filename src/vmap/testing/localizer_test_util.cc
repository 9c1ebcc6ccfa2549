#include "vmap/testing/localizer_test_util.h"

#include <limits>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "vmap/features/orb_matcher.h"
#include "vmap/localization/key_bracket.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap::testing {

namespace {

// A map of the drive's even frames built with ORB at `tau` into a temporary folder, and opened.
struct DriveMap {
  ScopedTempDir directory;
  LocalizationMap opened;
  explicit DriveMap(double tau) {
    const auto matcher = CreateOrbMatcher({});
    MapBuilderOptions options;
    options.show_progress = false;
    options.key_images.tau = tau;
    MemorySource source(DriveFrames(0, 2), DriveIndices(0, 2));
    BuildMapDirectory(source, *matcher, options, directory.path() / "map");
    opened = OpenLocalizationMap(directory.path() / "map", {});
  }
};

}  // namespace

const LocalizationMap& EvenDriveMap() {
  static const DriveMap map(MapBuilderOptions().key_images.tau);
  return map.opened;
}

const LocalizationMap& DenseDriveMap() {
  static const DriveMap map(0.8);
  return map.opened;
}

Frame MakeFrame(const cv::Mat& image, int index, int source_index) {
  Frame frame;
  frame.index = index;
  frame.source_index = source_index;
  cv::cvtColor(image, frame.gray, cv::COLOR_BGR2GRAY);
  frame.color = image;
  return frame;
}

LocalizationResult LocalizeOnEvenMap(Localizer& localizer, const cv::Mat& image, int index, int source_index) {
  const Frame frame = MakeFrame(image, index, source_index);
  const auto features = EvenDriveMap().matcher->Extract(frame.gray);
  return localizer.Localize(frame, *features);
}

LocalizationResult LocalizeOnDenseMap(Localizer& localizer, int source_index, int index,
                                      std::vector<KeyComparison> given) {
  MemorySource source({SidewaysDrive().frames[source_index]}, {source_index});
  Frame frame = *source.Next();
  frame.index = index;
  const auto features = DenseDriveMap().matcher->Extract(frame.gray);
  return localizer.Localize(frame, *features, std::move(given));
}

LocalizationResult LocalizeFramesOnDenseMap(Localizer& localizer, const std::vector<int>& source_indices, int* index) {
  LocalizationResult r;
  for (const int source_index : source_indices) r = LocalizeOnDenseMap(localizer, source_index, (*index)++);
  return r;
}

bool Brackets(const VisualMap& map, int source_index, int key) {
  const auto [before, after] = KeysAround(map, source_index);
  return key >= 0 && (key == before || key == after);
}

KeyComparison GivenComparison(int key, bool seen, int verified, double log10_nfa) {
  KeyComparison c;
  c.key = key;
  c.matched = c.accepted = seen;
  c.num_verified = verified;
  c.similarity = 0.3;
  c.log10_nfa = seen ? log10_nfa : std::numeric_limits<double>::infinity();
  return c;
}

}  // namespace vmap::testing
