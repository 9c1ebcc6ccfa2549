#include "vmap/core/atomic_output.h"

#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(AtomicOutput, DirectoryAppearsOnlyOnCommit) {
  testing::TempDir tmp;
  const fs::path target = tmp.path() / "map";
  {
    AtomicOutputDirectory dir(target, "marker");
    std::ofstream(dir.path() / "a.txt") << "hello";
    EXPECT_FALSE(fs::exists(target));
    dir.Commit();
  }
  EXPECT_EQ(ReadAll(target / "a.txt"), "hello");
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

TEST(AtomicOutput, UncommittedDirectoryLeavesNothingAndKeepsTheOldOne) {
  testing::TempDir tmp;
  const fs::path target = tmp.path() / "map";
  fs::create_directories(target);
  std::ofstream(target / "old.txt") << "old";
  std::ofstream(target / "marker") << "";
  {
    AtomicOutputDirectory dir(target, "marker");
    std::ofstream(dir.path() / "new.txt") << "new";
    // destroyed without Commit: as if the build failed half-way
  }
  EXPECT_TRUE(fs::exists(target / "old.txt"));
  EXPECT_FALSE(fs::exists(target / "new.txt"));
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

TEST(AtomicOutput, CommitReplacesAnOlderDirectory) {
  testing::TempDir tmp;
  const fs::path target = tmp.path() / "map";
  fs::create_directories(target);
  std::ofstream(target / "old.txt") << "old";
  std::ofstream(target / "marker") << "";
  AtomicOutputDirectory dir(target, "marker");
  std::ofstream(dir.path() / "new.txt") << "new";
  dir.Commit();
  EXPECT_FALSE(fs::exists(target / "old.txt"));
  EXPECT_EQ(ReadAll(target / "new.txt"), "new");
}

TEST(AtomicOutput, RefusesToReplaceAFile) {
  testing::TempDir tmp;
  std::ofstream(tmp.path() / "file") << "x";
  EXPECT_THROW(AtomicOutputDirectory(tmp.path() / "file", "marker"), InputError);
}

TEST(AtomicOutput, NeverReplacesADirectoryItDoesNotOwn) {
  testing::TempDir tmp;
  const fs::path target = tmp.path() / "documents";
  fs::create_directories(target);
  std::ofstream(target / "thesis.tex") << "precious";
  EXPECT_THROW(AtomicOutputDirectory(target, "map.json"), InputError);
  EXPECT_EQ(ReadAll(target / "thesis.tex"), "precious");
  // An empty directory may be used.
  fs::create_directories(tmp.path() / "empty");
  AtomicOutputDirectory empty(tmp.path() / "empty", "map.json");
  empty.Commit();
}

TEST(AtomicOutput, WriteFileAtomicallyWritesContentAndNoTemporaries) {
  testing::TempDir tmp;
  WriteFileAtomically(tmp.path() / "f.json", "{\"a\": 1}");
  EXPECT_EQ(ReadAll(tmp.path() / "f.json"), "{\"a\": 1}");
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
  EXPECT_THROW(WriteFileAtomically(tmp.path() / "missing_dir" / "f.json", "x"), InputError);
}

}  // namespace vmap
