#include "vmap/localization/key_image_store.h"

#include <chrono>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/features/orb_matcher.h"
#include "vmap/map/map_io.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;
namespace {

// A small map in a fresh directory.
struct SmallMap {
  ::vmap::testing::ScopedTempDir directory;
  fs::path path;
  VisualMap map;
  SmallMap() : path(directory.path() / "map") {
    ::vmap::testing::SyntheticOptions options;
    options.num_frames = 24;
    options.step = 0.08;
    const auto sequence = ::vmap::testing::RenderSyntheticSequence(options);
    const auto matcher = CreateOrbMatcher({});
    MapBuilderOptions build;
    build.show_progress = false;
    ::vmap::testing::MemorySource source(sequence.frames);
    map = ::vmap::testing::BuildMapDirectory(source, *matcher, build, path);
  }
};

void ExpectSameFeatures(const KeyImageStore& a, const KeyImageStore& b) {
  ASSERT_EQ(a.features.size(), b.features.size());
  for (size_t k = 0; k < a.features.size(); ++k) {
    EXPECT_EQ(a.features[k]->num_features(), b.features[k]->num_features());
    EXPECT_EQ(a.features[k]->image_size(), b.features[k]->image_size());
    EXPECT_EQ(cv::norm(a.features[k]->descriptors(), b.features[k]->descriptors(), cv::NORM_HAMMING), 0.0);
    EXPECT_EQ(cv::norm(a.thumbnails[k], b.thumbnails[k], cv::NORM_INF), 0.0);
  }
}

TEST(KeyImageStore, ComputesOnceThenReadsTheCache) {
  SmallMap m;
  ASSERT_GE(m.map.key_images.size(), 2u);
  const auto matcher = CreateOrbMatcher({});
  const KeyImageStore first = LoadKeyImageStore(m.path, m.map, *matcher, {});
  EXPECT_EQ(first.cache, KeyImageCacheState::kWritten);
  EXPECT_TRUE(fs::exists(m.path / kLocalizationCacheFileName));
  ASSERT_EQ(first.features.size(), m.map.key_images.size());
  const KeyImageStore second = LoadKeyImageStore(m.path, m.map, *matcher, {});
  EXPECT_EQ(second.cache, KeyImageCacheState::kHit);
  ExpectSameFeatures(first, second);
  // The cached features match exactly as fresh ones do.
  const auto a = matcher->Match(*first.features[0], *first.features[1]);
  const auto b = matcher->Match(*second.features[0], *second.features[1]);
  EXPECT_EQ(a.points0, b.points0);
  EXPECT_EQ(a.points1, b.points1);
}

TEST(KeyImageStore, AChangedMapOrMatcherMakesTheCacheStale) {
  SmallMap m;
  const auto matcher = CreateOrbMatcher({});
  ASSERT_EQ(LoadKeyImageStore(m.path, m.map, *matcher, {}).cache, KeyImageCacheState::kWritten);
  // Another ORB setting: recomputed, with that setting's features.
  OrbMatcherOptions fewer;
  fewer.num_features = 100;
  const auto other = CreateOrbMatcher(fewer);
  const KeyImageStore recomputed = LoadKeyImageStore(m.path, m.map, *other, {});
  EXPECT_EQ(recomputed.cache, KeyImageCacheState::kWritten);
  EXPECT_LE(recomputed.features[0]->num_features(), 100);
  EXPECT_EQ(LoadKeyImageStore(m.path, m.map, *other, {}).cache, KeyImageCacheState::kHit);
  // A rewritten map.json (a rebuilt map): recomputed.
  {
    std::ofstream out(m.path / kMapFileName, std::ios::app);
    out << "\n";
  }
  EXPECT_EQ(LoadKeyImageStore(m.path, m.map, *other, {}).cache, KeyImageCacheState::kWritten);
  // Another thumbnail width: recomputed.
  KeyImageStoreOptions wider;
  wider.thumbnail_width = 64;
  const KeyImageStore wide = LoadKeyImageStore(m.path, m.map, *other, wider);
  EXPECT_EQ(wide.cache, KeyImageCacheState::kWritten);
  EXPECT_EQ(wide.thumbnails[0].cols, 64 * 48);
}

TEST(KeyImageStore, AReplacedKeyImageMakesTheCacheStale) {
  SmallMap m;
  const auto matcher = CreateOrbMatcher({});
  ASSERT_EQ(LoadKeyImageStore(m.path, m.map, *matcher, {}).cache, KeyImageCacheState::kWritten);
  ASSERT_EQ(LoadKeyImageStore(m.path, m.map, *matcher, {}).cache, KeyImageCacheState::kHit);
  // Key image 1's file copied over key image 0's: map.json is as it was, the features are not.
  const fs::path first = m.path / m.map.key_images[0].image_file;
  fs::copy_file(m.path / m.map.key_images[1].image_file, first, fs::copy_options::overwrite_existing);
  fs::last_write_time(first, fs::last_write_time(first) + std::chrono::seconds(1));  // a coarse clock's copy too
  const KeyImageStore reloaded = LoadKeyImageStore(m.path, m.map, *matcher, {});
  EXPECT_EQ(reloaded.cache, KeyImageCacheState::kWritten);
  EXPECT_EQ(cv::norm(reloaded.features[0]->descriptors(), reloaded.features[1]->descriptors(), cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(LoadKeyImageStore(m.path, m.map, *matcher, {}).cache, KeyImageCacheState::kHit);
}

TEST(KeyImageStore, ACacheDamagedInPlaceIsRecomputed) {
  SmallMap m;
  const auto matcher = CreateOrbMatcher({});
  const KeyImageStore fresh = LoadKeyImageStore(m.path, m.map, *matcher, {});
  const fs::path cache = m.path / kLocalizationCacheFileName;
  // Bytes in the middle of the features flipped, the size unchanged: every piece still parses.
  {
    std::fstream file(cache, std::ios::in | std::ios::out | std::ios::binary);
    const auto middle = static_cast<std::streamoff>(fs::file_size(cache) / 2);
    std::string bytes(64, '\0');
    file.seekg(middle);
    file.read(bytes.data(), 64);
    for (char& c : bytes) c = static_cast<char>(~c);
    file.seekp(middle);
    file.write(bytes.data(), 64);
  }
  const KeyImageStore again = LoadKeyImageStore(m.path, m.map, *matcher, {});
  EXPECT_EQ(again.cache, KeyImageCacheState::kWritten);
  ExpectSameFeatures(fresh, again);
}

TEST(KeyImageStore, ACorruptCacheIsRecomputedAndNoCacheMeansNoFile) {
  SmallMap m;
  const auto matcher = CreateOrbMatcher({});
  const KeyImageStore fresh = LoadKeyImageStore(m.path, m.map, *matcher, {});
  const fs::path cache = m.path / kLocalizationCacheFileName;
  fs::resize_file(cache, fs::file_size(cache) / 2);
  const KeyImageStore again = LoadKeyImageStore(m.path, m.map, *matcher, {});
  EXPECT_EQ(again.cache, KeyImageCacheState::kWritten);
  ExpectSameFeatures(fresh, again);
  fs::remove(cache);
  KeyImageStoreOptions off;
  off.use_cache = false;
  EXPECT_EQ(LoadKeyImageStore(m.path, m.map, *matcher, off).cache, KeyImageCacheState::kOff);
  EXPECT_FALSE(fs::exists(cache));
}

}  // namespace
}  // namespace vmap
