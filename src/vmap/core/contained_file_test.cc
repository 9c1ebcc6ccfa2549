#include "vmap/core/contained_file.h"

#include <sys/stat.h>

#include <ctime>
#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

std::string WhyNot(const fs::path& directory, const std::string& relative) {
  std::string why_not;
  return ContainedFile::Open(directory, relative, &why_not) ? std::string() : why_not;
}

}  // namespace

TEST(ContainedFile, OpensRegularFilesInsideAndReadsRanges) {
  testing::ScopedTempDir tmp;
  fs::create_directories(tmp.path() / "map/keys");
  std::ofstream(tmp.path() / "map/keys/a.bin") << "0123456789";
  // A link that stays inside is fine.
  fs::create_symlink("keys/a.bin", tmp.path() / "map/inside_link.bin");
  for (const std::string relative : {"keys/a.bin", "inside_link.bin", "keys/./a.bin"}) {
    std::string why_not;
    const std::optional<ContainedFile> file = ContainedFile::Open(tmp.path() / "map", relative, &why_not);
    ASSERT_TRUE(file) << relative << ": " << why_not;
    EXPECT_EQ(file->size(), 10u);
    char middle[4] = {};
    ASSERT_TRUE(file->Read(3, middle, 3));
    EXPECT_STREQ(middle, "345");
    EXPECT_FALSE(file->Read(8, middle, 3)) << "past the end";
  }
}

TEST(ContainedFile, RefusesWhatLeadsOutOrIsNotAFile) {
  testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  fs::create_directories(map / "keys");
  std::ofstream(tmp.path() / "secret.txt") << "secret";
  fs::create_symlink(tmp.path() / "secret.txt", map / "absolute_link");
  fs::create_symlink("../secret.txt", map / "relative_link");
  fs::create_symlink("/dev/zero", map / "zero");
  fs::create_directory_symlink(tmp.path(), map / "up");
  ASSERT_EQ(mkfifo((map / "fifo").c_str(), 0600), 0);
  EXPECT_EQ(WhyNot(map, "missing.bin"), "is missing");
  EXPECT_NE(WhyNot(map, "../secret.txt").find("points outside"), std::string::npos);
  EXPECT_NE(WhyNot(map, (tmp.path() / "secret.txt").string()).find("points outside"), std::string::npos);
  for (const std::string link : {"absolute_link", "relative_link", "zero", "up/secret.txt"}) {
    EXPECT_NE(WhyNot(map, link).find("resolves outside"), std::string::npos) << link;
  }
  EXPECT_EQ(WhyNot(map, "fifo"), "is not a regular file") << "and opening it did not wait for a writer";
  EXPECT_EQ(WhyNot(map, "keys"), "is not a regular file");
  EXPECT_EQ(WhyNot("/dev", "zero"), "is not a regular file");
}

TEST(ContainedFile, IsSameOrInsideComparesWhatPathsResolveTo) {
  testing::ScopedTempDir tmp;
  fs::create_directories(tmp.path() / "a/b");
  fs::create_directory_symlink(tmp.path() / "a/b", tmp.path() / "link_to_b");
  EXPECT_TRUE(IsSameOrInside(tmp.path() / "a/b", tmp.path() / "a"));
  EXPECT_TRUE(IsSameOrInside(tmp.path() / "a", tmp.path() / "a"));
  EXPECT_TRUE(IsSameOrInside(tmp.path() / "link_to_b", tmp.path() / "a"));
  EXPECT_TRUE(IsSameOrInside(tmp.path() / "a/b/not_yet/x", tmp.path() / "link_to_b"));
  EXPECT_TRUE(IsSameOrInside(tmp.path() / "a/../a/b", tmp.path() / "a"));
  EXPECT_FALSE(IsSameOrInside(tmp.path() / "a", tmp.path() / "a/b"));
  EXPECT_FALSE(IsSameOrInside(tmp.path() / "ab", tmp.path() / "a"));
  EXPECT_FALSE(IsSameOrInside(tmp.path() / "a", tmp.path() / "missing"));
}

TEST(ContainedFile, ReadsJsonWithLimits) {
  testing::ScopedTempDir tmp;
  std::ofstream(tmp.path() / "ok.json") << R"({"format": "x", "n": [1, 2]})";
  ContainedJson ok = ReadContainedJson(tmp.path(), "ok.json", 1000, 1000);
  ASSERT_TRUE(ok.document) << ok.why_not;
  EXPECT_EQ((*ok.document)["n"][1], 2);
  EXPECT_TRUE(ReadContainedJson(tmp.path(), "missing.json", 1000, 1000).missing);
  EXPECT_NE(ReadContainedJson(tmp.path(), "ok.json", 10, 1000).why_not.find("larger than"), std::string::npos);
  std::ofstream(tmp.path() / "deep.json") << std::string(100000, '[') << std::string(100000, ']');
  EXPECT_NE(ReadContainedJson(tmp.path(), "deep.json", 1 << 20, 1000).why_not.find("nested"), std::string::npos);
  std::ofstream(tmp.path() / "huge_number.json") << R"({"n": 1e999})";
  EXPECT_NE(ReadContainedJson(tmp.path(), "huge_number.json", 1000, 1000).why_not.find("number too large"),
            std::string::npos);
  std::ofstream(tmp.path() / "bad.json") << R"({"n": )";
  EXPECT_NE(ReadContainedJson(tmp.path(), "bad.json", 1000, 1000).why_not.find("not valid JSON"), std::string::npos);
  // Many values in few bytes: refused by their count, before they are all held.
  std::string many = "[0";
  for (int i = 0; i < 2000; ++i) many += ",0";
  std::ofstream(tmp.path() / "many.json") << many << "]";
  EXPECT_NE(ReadContainedJson(tmp.path(), "many.json", 1 << 20, 1000).why_not.find("more than 1000 values"),
            std::string::npos);
  EXPECT_TRUE(ReadContainedJson(tmp.path(), "many.json", 1 << 20, 3000).document);
}

// Issue 38: a map.json of 400,000 small objects took `vmap info` 41 s, the parser searching each object's
// parent after it (quadratic). 200,000 objects take well under a second now; before, about 15 s.
TEST(ContainedFile, JsonOfManySmallObjectsParsesInLinearTime) {
  testing::ScopedTempDir tmp;
  {
    std::ofstream out(tmp.path() / "objects.json");
    out << R"({"format": "x", "padding": [)";
    for (int i = 0; i < 200000; ++i) out << (i ? "," : "") << R"({"a":)" << i << "}";
    out << "]}";
  }
  // CPU time (std::clock: this process's), which other processes' load on a shared machine does not stretch.
  const std::clock_t start = std::clock();
  const ContainedJson parsed = ReadContainedJson(tmp.path(), "objects.json", 1 << 30, 1 << 23);
  const double seconds = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  ASSERT_TRUE(parsed.document) << parsed.why_not;
  EXPECT_EQ((*parsed.document)["padding"].size(), 200000u);
  EXPECT_EQ((*parsed.document)["padding"][199999]["a"], 199999);
  EXPECT_LT(seconds, 5.0) << "quadratic again?";
}

TEST(ContainedFile, NamedFilesMustBeRegular) {
  testing::ScopedTempDir tmp;
  std::ofstream(tmp.path() / "gt.txt") << "1 2 3";
  EXPECT_EQ(ReadNamedFile(tmp.path() / "gt.txt", 100, "ground truth", "fix"), "1 2 3");
  ASSERT_EQ(mkfifo((tmp.path() / "fifo").c_str(), 0600), 0);
  const auto message = [&](const fs::path& path, std::uint64_t max_bytes) {
    try {
      ReadNamedFile(path, max_bytes, "ground truth", "give a poses file");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("read");
  };
  // A FIFO without a writer would block a plain open; a device would be read forever.
  EXPECT_NE(message(tmp.path() / "fifo", 100).find("not a regular file"), std::string::npos);
  EXPECT_NE(message("/dev/zero", 100).find("not a regular file"), std::string::npos);
  EXPECT_NE(message(tmp.path(), 100).find("not a regular file"), std::string::npos);
  EXPECT_NE(message(tmp.path() / "missing", 100).find("is missing; give a poses file"), std::string::npos);
  EXPECT_NE(message(tmp.path() / "gt.txt", 2).find("larger than"), std::string::npos);
}

}  // namespace vmap
