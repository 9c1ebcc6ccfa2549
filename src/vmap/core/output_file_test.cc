#include "vmap/core/output_file.h"

#include <sys/stat.h>

#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/testing/promises_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

std::string Refusal(const std::vector<OutputFile>& outputs, const std::vector<OutputInput>& inputs) {
  try {
    CheckOutputFiles(outputs, inputs);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(OutputFile, InputsAreNeverOutputs) {
  testing::ScopedTempDir tmp;
  fs::create_directories(tmp.path() / "map/keys");
  std::ofstream(tmp.path() / "map/map.json") << "{}";
  std::ofstream(tmp.path() / "query.png") << "png";
  fs::create_symlink(tmp.path() / "query.png", tmp.path() / "query_link.png");
  fs::create_hard_link(tmp.path() / "query.png", tmp.path() / "query_hard.png");
  const std::vector<OutputInput> inputs = {{tmp.path() / "map/map.json", "the map's map.json"},
                                           {tmp.path() / "map/keys", "the map's keys"},
                                           {tmp.path() / "map/cache.bin", "the map's cache"},
                                           {tmp.path() / "query.png", "the query"}};
  const auto refusal = [&](const fs::path& output) { return Refusal({{output, "--csv"}}, inputs); };
  EXPECT_NE(refusal(tmp.path() / "query.png")
                .find("--csv '" + (tmp.path() / "query.png").string() + "' would overwrite the query '"),
            std::string::npos);
  EXPECT_NE(refusal(tmp.path() / "map/keys/../map.json").find("would overwrite the map's map.json"), std::string::npos);
  EXPECT_NE(refusal(tmp.path() / "query_hard.png").find("would overwrite the query"), std::string::npos);
  // A symbolic link to an input is refused as that input, the worse of its two faults.
  EXPECT_NE(refusal(tmp.path() / "query_link.png").find("would overwrite the query"), std::string::npos);
  EXPECT_NE(refusal(tmp.path() / "map/keys/new.png").find("lies inside the map's keys"), std::string::npos);
  // Not there yet, but this run or the next may write it.
  EXPECT_NE(refusal(tmp.path() / "map/cache.bin").find("would overwrite the map's cache"), std::string::npos);
  EXPECT_EQ(refusal(tmp.path() / "map/new.csv"), "");
  EXPECT_EQ(refusal(tmp.path() / "out.csv"), "");
  EXPECT_NE(Refusal({{tmp.path() / "a.csv", "--csv"}, {tmp.path() / "./a.csv", "--json"}}, {})
                .find("--json '" + (tmp.path() / "./a.csv").string() + "' is also the output of --csv"),
            std::string::npos);
  EXPECT_EQ(Refusal({{"", "--csv"}, {"", "--json"}}, inputs), "");  // not asked for
}

// Issue 38: `--csv h.png`, h.png a hard link of an image inside the query folder, was written (renamed over).
TEST(OutputFile, AHardLinkOfAFileInsideAnInputFolderIsThatFile) {
  testing::ScopedTempDir tmp;
  fs::create_directories(tmp.path() / "query/sub");
  std::ofstream(tmp.path() / "query/sub/0001.png") << "png";
  fs::create_hard_link(tmp.path() / "query/sub/0001.png", tmp.path() / "h.png");
  std::ofstream(tmp.path() / "other.png") << "png";
  fs::create_hard_link(tmp.path() / "other.png", tmp.path() / "other_link.png");
  const std::vector<OutputInput> inputs = {{tmp.path() / "query", "the query"}};
  EXPECT_NE(Refusal({{tmp.path() / "h.png", "--csv"}}, inputs).find("is a hard link of '"), std::string::npos);
  EXPECT_EQ(Refusal({{tmp.path() / "other_link.png", "--csv"}}, inputs), "");  // links, but of no input
}

TEST(OutputFile, OnlyWritableRegularFilesAreReplaced) {
  testing::ScopedTempDir tmp;
  std::ofstream(tmp.path() / "old.csv") << "old";
  std::ofstream(tmp.path() / "target.csv") << "target";
  fs::create_symlink(tmp.path() / "target.csv", tmp.path() / "link.csv");
  std::ofstream(tmp.path() / "readonly.csv") << "kept";
  fs::permissions(tmp.path() / "readonly.csv", fs::perms::owner_read);
  ASSERT_EQ(mkfifo((tmp.path() / "fifo.csv").c_str(), 0600), 0);
  std::ofstream(tmp.path() / "script.json") << "#!/bin/sh\necho hi\n";
  std::ofstream(tmp.path() / "binary.json") << "\x7f"
                                               "ELF\x02\x01";
  const auto refusal = [&](const fs::path& output) { return Refusal({{output, "-o"}}, {}); };
  EXPECT_EQ(refusal(tmp.path() / "old.csv"), "");
  EXPECT_NE(refusal(tmp.path() / "link.csv").find("is a symbolic link"), std::string::npos);
  EXPECT_NE(refusal(tmp.path() / "readonly.csv").find("is read-only"), std::string::npos);
  EXPECT_NE(refusal(tmp.path() / "fifo.csv").find("is not a regular file"), std::string::npos);
  // A program in the way is a slip of the path, never an earlier run's output; whatever its mode bits.
  EXPECT_NE(refusal(tmp.path() / "script.json").find("is a program"), std::string::npos);
  EXPECT_NE(refusal(tmp.path() / "binary.json").find("is a program"), std::string::npos);
  EXPECT_NE(refusal("/dev/null").find("is not a regular file"), std::string::npos);
  EXPECT_NE(refusal(tmp.path()).find("is a folder"), std::string::npos);
  EXPECT_NE(refusal(tmp.path() / "missing/out.csv").find("does not exist"), std::string::npos);
  // What the file system will refuse, refused before the work: a name too long, a folder no file can be made in.
  EXPECT_NE(refusal(tmp.path() / (std::string(300, 'a') + ".json")).find("cannot be written: File name too long"),
            std::string::npos);
  EXPECT_NE(refusal("/proc/vmap_out.json").find("cannot be written"), std::string::npos);
  EXPECT_EQ(refusal(tmp.path() / "new.csv"), "");
  EXPECT_FALSE(fs::exists(tmp.path() / "new.csv"));
  EXPECT_TRUE(testing::EntriesStartingWith(tmp.path(), ".new.csv").empty());

  // WriteFileAtomically, which every output goes through, holds to the same rule on its own.
  const auto write_refusal = [&](const fs::path& output) {
    try {
      WriteFileAtomically(output, "new");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  EXPECT_EQ(write_refusal(tmp.path() / "old.csv"), "");
  EXPECT_EQ(ReadAll(tmp.path() / "old.csv"), "new");
  EXPECT_NE(write_refusal(tmp.path() / "link.csv").find("symbolic link"), std::string::npos);
  EXPECT_NE(write_refusal(tmp.path() / "readonly.csv").find("read-only"), std::string::npos);
  EXPECT_NE(write_refusal(tmp.path() / "fifo.csv").find("not a regular file"), std::string::npos);
  EXPECT_NE(write_refusal(tmp.path() / "binary.json").find("is a program"), std::string::npos);
  EXPECT_EQ(ReadAll(tmp.path() / "script.json"), "#!/bin/sh\necho hi\n");
  EXPECT_NE(write_refusal("/dev/null").find("not a regular file"), std::string::npos);
  EXPECT_TRUE(fs::is_symlink(tmp.path() / "link.csv"));
  EXPECT_EQ(ReadAll(tmp.path() / "target.csv"), "target");
  EXPECT_EQ(ReadAll(tmp.path() / "readonly.csv"), "kept");
  EXPECT_TRUE(fs::is_fifo(tmp.path() / "fifo.csv"));
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  // Nothing left behind by the refusals.
  for (const auto& entry : fs::directory_iterator(tmp.path())) {
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
  }
}

}  // namespace vmap
