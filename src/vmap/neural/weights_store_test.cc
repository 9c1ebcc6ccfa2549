// `vmap weights` without a network: SHA-1 / git blob ids, the cache, and the search order.

#include "vmap/neural/weights_store.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/neural/sha1.h"
#include "vmap/testing/shared_data.h"

namespace vmap::neural {
namespace {

namespace fs = std::filesystem;

// Points VMAP_WEIGHTS_DIR at a fresh directory for one test and restores the variable afterwards.
class WeightsStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cache_ = fs::temp_directory_path() / ("vmap_store_test_" + std::to_string(getpid()) + "_" +
                                          ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(cache_);
    if (const char* old = std::getenv(kWeightsDirEnv)) saved_ = old, had_value_ = true;
    setenv(kWeightsDirEnv, cache_.c_str(), 1);
  }
  void TearDown() override {
    if (had_value_)
      setenv(kWeightsDirEnv, saved_.c_str(), 1);
    else
      unsetenv(kWeightsDirEnv);
    fs::remove_all(cache_);
  }
  std::string WriteFile(const std::string& name, const std::string& contents) {
    fs::create_directories(cache_.parent_path());
    const auto path = (cache_.parent_path() / (cache_.filename().string() + "_" + name)).string();
    std::ofstream(path, std::ios::binary) << contents;
    created_.push_back(path);
    return path;
  }
  ~WeightsStoreTest() override {
    for (const auto& p : created_) fs::remove(p);
  }
  fs::path cache_;
  std::string saved_;
  bool had_value_ = false;
  std::vector<std::string> created_;
};

TEST(Sha1, KnownVectors) {
  EXPECT_EQ(Sha1Hex(""), "da39a3ee5e6b4b0d3255bfef95601890afd80709");
  EXPECT_EQ(Sha1Hex("abc"), "a9993e364706816aba3e25717850c26c9cd0d89d");
  EXPECT_EQ(Sha1Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "84983e441c3bd26ebaae4aa1f95129e5e54670f1");
  EXPECT_EQ(Sha1Hex(std::string(1000000, 'a')), "34aa973cd4c4daa4f61eeb2bdbad27316534016f");
}

TEST_F(WeightsStoreTest, GitBlobIdOfFiles) {
  // `git hash-object` of "hello\n" and of an empty file.
  EXPECT_EQ(GitBlobId(WriteFile("hello", "hello\n")), "ce013625030ba8dba906f756967f9e9ca394464a");
  EXPECT_EQ(GitBlobId(WriteFile("empty", "")), "e69de29bb2d1d6434b8b29ae775ad8c2e48c5391");
  EXPECT_THROW(GitBlobId((cache_ / "absent").string()), InputError);
}

// A weights file given by a relative name is located by its absolute path: a map records it, and a command run
// elsewhere would otherwise read another file of that name, or none.
TEST_F(WeightsStoreTest, AWeightsFileGivenRelativeIsLocatedByItsAbsolutePath) {
  const fs::path file = WriteFile("relative.ckpt", "weights\n");
  const fs::path before = fs::current_path();
  fs::current_path(file.parent_path());
  const std::string located = LocateWeights("outdoor", file.filename().string());
  fs::current_path(before);
  EXPECT_EQ(located, file.string());
  EXPECT_TRUE(fs::path(located).is_absolute());
}

TEST_F(WeightsStoreTest, CacheDirectoryFollowsEnvironment) {
  EXPECT_EQ(WeightsCacheDir(), cache_.string());
  EXPECT_EQ(WeightsSearchPaths("outdoor").front(), cache_.string() + "/outdoor_ds.ckpt");
}

TEST_F(WeightsStoreTest, ImportVerifiesAndLandsInCache) {
  const std::string file = WriteFile("download.ckpt", "hello\n");
  EXPECT_THROW(LocateWeights("outdoor", ""), InputError);
  const std::string cached = ImportWeights(file, "outdoor", "ce013625030ba8dba906f756967f9e9ca394464a", cache_);
  EXPECT_EQ(cached, cache_.string() + "/outdoor_ds.ckpt");
  EXPECT_EQ(GitBlobId(cached), "ce013625030ba8dba906f756967f9e9ca394464a");
  EXPECT_EQ(LocateWeights("outdoor", ""), cached);
  // Other presets are still missing.
  EXPECT_THROW(LocateWeights("indoor", ""), InputError);
}

TEST_F(WeightsStoreTest, MismatchedBlobIdIsRejectedAndNothingIsWritten) {
  const std::string file = WriteFile("tampered.ckpt", "hello!\n");
  try {
    ImportWeights(file, "indoor", KnownWeightsFor("indoor").git_blob_id, cache_);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(KnownWeightsFor("indoor").git_blob_id), std::string::npos) << message;
    EXPECT_NE(message.find(GitBlobId(file)), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(cache_ / "indoor_ds_new.ckpt"));
}

TEST_F(WeightsStoreTest, MissingWeightsErrorSaysWhereAndHow) {
  try {
    LocateWeights("indoor", "");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(cache_.string() + "/indoor_ds_new.ckpt"), std::string::npos) << message;
    EXPECT_NE(message.find("vmap weights --download indoor"), std::string::npos) << message;
    EXPECT_NE(message.find(kWeightsDirEnv), std::string::npos) << message;
  }
  EXPECT_THROW(LocateWeights("coarse", (cache_ / "nope.pt").string()), InputError);
}

TEST_F(WeightsStoreTest, CoarseStudentDefaultsToSharedCopy) {
  if (!fs::exists(testing::SharedDir() + "/weights/loftr_coarse/loftr_coarse_teacher.pt")) {
    GTEST_SKIP() << "no shared weights";
  }
  const std::string found = LocateWeights("coarse", "");
  EXPECT_NE(found.find("loftr_coarse/loftr_coarse_teacher.pt"), std::string::npos) << found;
  // A cached copy takes precedence over the shared one.
  const std::string cached = ImportWeights(found, "coarse", "", cache_);
  EXPECT_EQ(LocateWeights("coarse", ""), cached);
}

TEST_F(WeightsStoreTest, UnknownPreset) { EXPECT_THROW(KnownWeightsFor("huge"), InputError); }

}  // namespace
}  // namespace vmap::neural
