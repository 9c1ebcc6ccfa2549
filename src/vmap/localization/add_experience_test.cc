#include "vmap/localization/add_experience.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/directory_lock.h"
#include "vmap/core/error.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/localization/localization_map.h"
#include "vmap/map/map_io.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using ::vmap::testing::MemorySource;
using ::vmap::testing::ScopedTempDir;

const ::vmap::testing::SyntheticSequence& Drive() {
  static const auto sequence = [] {
    ::vmap::testing::SyntheticOptions options;
    options.num_frames = 40;
    options.step = 0.05;
    options.yaw_per_frame = 0.003;
    return ::vmap::testing::RenderSyntheticSequence(options);
  }();
  return sequence;
}

// The same place in another "season": the right half's intensities inverted, which ORB's binary tests do not
// survive, so that a frame of it shares only the left half with the teach run's key images.
cv::Mat OtherSeason(const cv::Mat& image) {
  cv::Mat changed = image.clone();
  cv::Mat right = changed.colRange(image.cols / 2, image.cols);
  right = cv::Scalar::all(255) - right;
  return changed;
}

std::vector<cv::Mat> Frames(int first, int stride, bool other_season = false) {
  std::vector<cv::Mat> frames;
  for (int i = first; i < static_cast<int>(Drive().frames.size()); i += stride) {
    frames.push_back(other_season ? OtherSeason(Drive().frames[i]) : Drive().frames[i]);
  }
  return frames;
}

// Every file of a folder with its bytes: what "left as it was" compares.
std::map<std::string, std::string> Snapshot(const fs::path& directory) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(directory)) {
    const std::string name = fs::relative(entry.path(), directory).string();
    files[name] = entry.is_regular_file() ? ::vmap::testing::ReadText(entry.path()) : "<dir>";
  }
  return files;
}

// A map of every 4th frame of the drive, written into a fresh folder.
struct TeachMap {
  ScopedTempDir tmp;
  fs::path path;
  TeachMap() : path(tmp.path() / "map") {
    const auto matcher = CreateOrbMatcher({});
    MapBuilderOptions options;
    options.show_progress = false;
    MemorySource source(Frames(0, 4));
    ::vmap::testing::BuildMapDirectory(source, *matcher, options, path);
  }
};

AddExperienceOptions Quiet() {
  AddExperienceOptions options;
  options.run.show_progress = false;
  return options;
}

TEST(AddExperience, AddsViewsAndKeepsTheTeachRunByteIdentical) {
  TeachMap map;
  const std::string json_before = ::vmap::testing::ReadText(map.path / kMapFileName);
  const std::string correspondences_before = ::vmap::testing::ReadText(map.path / kCorrespondencesFileName);
  const VisualMap before = ReadMap(map.path);
  std::map<std::string, std::string> keys_before = Snapshot(map.path / "keys");

  MemorySource repeat(Frames(2, 4, /*other_season=*/true));
  const AddExperienceSummary added = AddExperience(map.path, repeat, "repeat", Quiet());
  EXPECT_EQ(added.experience.id, 1);
  EXPECT_EQ(added.frames, 10);
  ASSERT_GE(added.experience.views.size(), before.key_images.size() / 2);

  // Key images, links and every other field as before; only `experiences` is new.
  EXPECT_EQ(::vmap::testing::ReadText(map.path / kCorrespondencesFileName), correspondences_before);
  EXPECT_EQ(Snapshot(map.path / "keys"), keys_before);
  nlohmann::json now = nlohmann::json::parse(::vmap::testing::ReadText(map.path / kMapFileName));
  ASSERT_TRUE(now.contains("experiences"));
  now.erase("experiences");
  EXPECT_EQ(now.dump(1) + "\n", json_before);

  // It reads back, as written.
  const VisualMap after = ReadMap(map.path);
  const std::vector<Experience> experiences = after.experiences;
  ASSERT_EQ(experiences.size(), 1u);
  EXPECT_EQ(experiences[0].source, "repeat");
  ASSERT_EQ(experiences[0].views.size(), added.experience.views.size());
  for (size_t i = 0; i < experiences[0].views.size(); ++i) {
    const ExperienceView& v = experiences[0].views[i];
    EXPECT_EQ(v.key, added.experience.views[i].key);
    EXPECT_EQ(v.frame_index, added.experience.views[i].frame_index);
    EXPECT_DOUBLE_EQ(v.heading_px, added.experience.views[i].heading_px);
    EXPECT_GE(v.num_verified, 20);
    EXPECT_TRUE(fs::is_regular_file(map.path / v.image_file)) << v.image_file;
    // The view (drive frame 2 + 4j) lies between the key images around its key image (drive frames 4 s, s
    // their source indices in the teach run).
    const int drive_frame = 2 + 4 * v.frame_index;
    const int before_key = v.key > 0 ? 4 * after.key_images[v.key - 1].source_index : 0;
    const int after_key = v.key + 1 < static_cast<int>(after.key_images.size())
                              ? 4 * after.key_images[v.key + 1].source_index
                              : static_cast<int>(Drive().frames.size());
    EXPECT_GT(drive_frame, before_key) << "view of key " << v.key;
    EXPECT_LT(drive_frame, after_key) << "view of key " << v.key;
  }

  // A second run becomes experience 2; the first stays.
  MemorySource again(Frames(1, 4, /*other_season=*/true));
  EXPECT_EQ(AddExperience(map.path, again, "again", Quiet()).experience.id, 2);
  const std::vector<Experience> two = ReadMap(map.path).experiences;
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].views.size(), experiences[0].views.size());
  EXPECT_EQ(::vmap::testing::ReadText(map.path / kCorrespondencesFileName), correspondences_before);
}

TEST(AddExperience, LocalizationPicksTheViewThatFitsAndHeadsAgainstTheKeyImage) {
  TeachMap map;
  MemorySource repeat(Frames(2, 4, /*other_season=*/true));
  AddExperience(map.path, repeat, "repeat", Quiet());
  const LocalizationMap opened = OpenLocalizationMap(map.path, {});
  ASSERT_EQ(opened.keys.views.size(), opened.map.key_images.size());
  LocalizerOptions with = MapLocalizerOptions(opened);
  LocalizerOptions without = with;
  without.experience_candidates = 0;
  const Localizer experienced(opened.map, opened.keys, *opened.matcher, with);
  const Localizer teach_only(opened.map, opened.keys, *opened.matcher, without);
  int accepted_with = 0, accepted_without = 0, from_view = 0, compared = 0, verified_with = 0, verified_without = 0;
  int close = 0;  // headings through a view within 3 px of the same frame's in the teach run's season
  for (int i = 1; i + 4 < static_cast<int>(Drive().frames.size()); i += 4) {
    const int key = KeysAround(opened.map, i / 4).first;  // the key image before drive frame i
    cv::Mat gray, other_gray;
    cv::cvtColor(Drive().frames[i], gray, cv::COLOR_BGR2GRAY);
    cv::cvtColor(OtherSeason(Drive().frames[i]), other_gray, cv::COLOR_BGR2GRAY);
    const auto features = opened.matcher->Extract(other_gray);
    const KeyComparison c = experienced.Compare(*features, key);
    const KeyComparison teach = teach_only.Compare(*features, key);
    EXPECT_EQ(teach.experience, 0);
    accepted_with += c.accepted;
    accepted_without += teach.accepted;
    verified_with += c.num_verified;
    verified_without += teach.num_verified;
    ++compared;
    if (c.experience == 0) continue;
    ++from_view;
    EXPECT_EQ(c.experience, 1);
    EXPECT_FALSE(c.pose.valid);
    // The heading against the key image, through the view, is the one the same frame in the teach run's
    // season has against it directly.
    const KeyComparison same_season = teach_only.Compare(*opened.matcher->Extract(gray), key);
    ASSERT_TRUE(same_season.accepted);
    // Not exactly: the scene's planes lie at several depths and the view was taken elsewhere on the path, so
    // the densest displacement may be another plane's.
    EXPECT_NEAR(c.heading.px, same_season.heading.px, 20.0) << "frame " << i;
    close += std::abs(c.heading.px - same_season.heading.px) <= 3.0;
  }
  EXPECT_GE(4 * close, 3 * from_view);
  EXPECT_GT(from_view, compared / 2);
  EXPECT_GE(accepted_with, accepted_without);
  EXPECT_GT(verified_with, verified_without * 3 / 2);
}

TEST(AddExperience, AMapWithoutExperiencesComparesAsBefore) {
  TeachMap map;
  const LocalizationMap opened = OpenLocalizationMap(map.path, {});
  EXPECT_TRUE(opened.experiences.empty());
  EXPECT_TRUE(opened.keys.views.empty());
  const Localizer localizer(opened.map, opened.keys, *opened.matcher, MapLocalizerOptions(opened));
  cv::Mat gray;
  cv::cvtColor(Drive().frames[5], gray, cv::COLOR_BGR2GRAY);
  const auto features = opened.matcher->Extract(gray);
  const KeyComparison c = localizer.Compare(*features, 1);
  const PairComparison pair =
      ComparePair(*opened.matcher, *features, *opened.keys.features[1], MapLocalizerOptions(opened).verifier,
                  opened.options.builder.key_images.similarity);
  EXPECT_EQ(c.experience, 0);
  EXPECT_EQ(c.num_verified, pair.num_verified);
  EXPECT_EQ(c.num_tentative, pair.num_tentative);
  EXPECT_EQ(c.F, pair.F);
}

TEST(AddExperience, AFailureLeavesTheMapAsItWas) {
  TeachMap map;
  const auto before = Snapshot(map.path);
  // Frames of another size: refused at the first frame, after the views' folder was begun.
  std::vector<cv::Mat> small;
  for (const cv::Mat& frame : Frames(2, 4)) {
    cv::Mat resized;
    cv::resize(frame, resized, cv::Size(160, 120));
    small.push_back(resized);
  }
  MemorySource other_size(small);
  try {
    AddExperience(map.path, other_size, "small", Quiet());
    FAIL() << "frames of another size were added";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--resize 320x240"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Snapshot(map.path), before);

  // A scene the map does not show: nothing localizes, nothing is added.
  cv::RNG rng(3);
  std::vector<cv::Mat> noise;
  for (int i = 0; i < 5; ++i) {
    cv::Mat image(240, 320, CV_8UC3);
    rng.fill(image, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(image, image, cv::Size(3, 3), 0);
    noise.push_back(image);
  }
  MemorySource elsewhere(noise);
  EXPECT_THROW(AddExperience(map.path, elsewhere, "elsewhere", Quiet()), InputError);
  EXPECT_EQ(Snapshot(map.path), before);

  // map.json cannot be replaced (read-only): refused before a frame is read, and nothing written.
  fs::permissions(map.path / kMapFileName, fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write,
                  fs::perm_options::remove);
  MemorySource repeat(Frames(2, 4, /*other_season=*/true));
  try {
    AddExperience(map.path, repeat, "repeat", Quiet());
    FAIL() << "an experience was added to a read-only map.json";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("map.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("read-only"), std::string::npos) << e.what();
  }
  const std::optional<Frame> first = repeat.Next();
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->index, 0) << "frames were read before the refusal";
  EXPECT_EQ(Snapshot(map.path), before);
}

TEST(AddExperience, RefusesWhatIsNotAMap) {
  ScopedTempDir tmp;
  fs::create_directories(tmp.path() / "not_a_map");
  MemorySource repeat(Frames(2, 4));
  EXPECT_THROW(AddExperience(tmp.path() / "not_a_map", repeat, "repeat", Quiet()), InputError);
  EXPECT_TRUE(fs::is_empty(tmp.path() / "not_a_map"));
}

// ---- Issue 38: concurrent writers, links inside the map, runs that were killed ------------------------------

TEST(AddExperience, TwoAddsAtOnceBothLandOneAfterTheOther) {
  // The case: two adds on one map at once. Each read map.json with no experience, both wrote
  // experience 1, and the loser's clean-up deleted `experiences/` under the winner's map.json.
  TeachMap map;
  std::string errors[2];
  int ids[2] = {0, 0};
  std::thread runs[2];
  for (int i = 0; i < 2; ++i) {
    runs[i] = std::thread([&, i] {
      try {
        MemorySource repeat(Frames(1 + i, 4, /*other_season=*/true));
        ids[i] = AddExperience(map.path, repeat, "repeat" + std::to_string(i), Quiet()).experience.id;
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    });
  }
  for (std::thread& run : runs) run.join();
  EXPECT_EQ(errors[0], "");
  EXPECT_EQ(errors[1], "");
  EXPECT_EQ(std::set<int>(ids, ids + 2), (std::set<int>{1, 2}));
  // Both are there, every view of each; and localization opens the map.
  const VisualMap after = ReadMap(map.path);
  ASSERT_EQ(after.experiences.size(), 2u);
  for (const Experience& experience : after.experiences) {
    for (const ExperienceView& view : experience.views) EXPECT_TRUE(fs::is_regular_file(map.path / view.image_file));
  }
  EXPECT_NO_THROW(OpenLocalizationMap(map.path, {}));
}

TEST(AddExperience, ASecondWriterWaitsForTheLockAndTouchesNothingMeanwhile) {
  TeachMap map;
  const auto before = Snapshot(map.path);
  std::optional<DirectoryWriteLock> other(std::in_place, map.path, "the map");  // another writer, in effect
  std::atomic<bool> done{false};
  std::thread add([&] {
    MemorySource repeat(Frames(2, 4, /*other_season=*/true));
    AddExperience(map.path, repeat, "repeat", Quiet());
    done = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(done);
  EXPECT_EQ(Snapshot(map.path), before);  // nothing read into a temporary, nothing written
  other.reset();
  add.join();
  EXPECT_TRUE(done);
  EXPECT_EQ(ReadMap(map.path).experiences.size(), 1u);
  EXPECT_FALSE(DirectoryWriteLock::IsHeldElsewhere(map.path));
}

TEST(AddExperience, WritesNothingThroughALinkInsideTheMap) {
  TeachMap map;
  const fs::path outside = map.tmp.path() / "outside";
  fs::create_directories(outside);
  fs::create_directory_symlink(outside, map.path / kExperiencesDirectory);
  const auto before = Snapshot(map.path);
  MemorySource repeat(Frames(2, 4, /*other_season=*/true));
  try {
    AddExperience(map.path, repeat, "repeat", Quiet());
    FAIL() << "an experience was written through a symbolic link";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("writes nothing through a link"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_empty(outside));
  EXPECT_EQ(Snapshot(map.path), before);
}

TEST(AddExperience, WhatAKilledAddLeftIsCleanedOrNamed) {
  TeachMap map;
  // A killed add's views (its pid runs no more): removed by the next add, which then lands.
  const fs::path stale = map.path / ".experiences.partial-999999999-7";
  fs::create_directories(stale / "1");
  std::ofstream(stale / "1/000000.png") << "half";
  MemorySource repeat(Frames(2, 4, /*other_season=*/true));
  EXPECT_EQ(AddExperience(map.path, repeat, "repeat", Quiet()).experience.id, 1);
  EXPECT_FALSE(fs::exists(stale));
  // An experience folder map.json does not list (killed between moving it in and writing map.json) is not
  // vmap's to remove: refused, naming it.
  fs::create_directories(map.path / kExperiencesDirectory / "2");
  const auto before = Snapshot(map.path);
  MemorySource again(Frames(1, 4, /*other_season=*/true));
  try {
    AddExperience(map.path, again, "again", Quiet());
    FAIL() << "experience 2 was written over an unlisted folder";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("map.json lists no experience 2"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Snapshot(map.path), before);
}

TEST(ExperienceViewPicker, KeepsTheFrameWithMostVerifiedMatchesPerKeyImage) {
  ExperienceViewPicker picker(3);
  auto result = [](int frame, int key, int verified, bool accepted) {
    LocalizationResult r;
    r.frame_index = r.source_index = frame;
    r.key = key;
    r.to_key.key = key;
    r.to_key.accepted = accepted;
    r.to_key.num_verified = verified;
    r.to_key.heading.px = frame;
    return r;
  };
  EXPECT_EQ(picker.Offer(result(0, 1, 30, true)), std::vector<int>{1});
  EXPECT_TRUE(picker.Offer(result(1, 1, 30, true)).empty());   // a tie keeps the earlier frame
  EXPECT_TRUE(picker.Offer(result(2, 2, 90, false)).empty());  // not accepted
  EXPECT_EQ(picker.Offer(result(3, 1, 45, true)), std::vector<int>{1});
  const std::vector<ExperienceView> views = picker.Views();
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].key, 1);
  EXPECT_EQ(views[0].frame_index, 3);
  EXPECT_EQ(views[0].num_verified, 45);
  EXPECT_DOUBLE_EQ(views[0].heading_px, 3.0);
}

}  // namespace
}  // namespace vmap
