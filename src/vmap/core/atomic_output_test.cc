#include "vmap/core/atomic_output.h"

#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

long CountEntries(const fs::path& directory) {
  return std::distance(fs::directory_iterator(directory), fs::directory_iterator());
}

// A test owner: a directory is ours when its "owner.txt" says "vmap".
OutputPolicy MarkerPolicy(std::vector<fs::path> inputs = {}) {
  OutputPolicy policy;
  policy.kind = "a test output";
  policy.why_not_ours = [](const fs::path& directory) {
    return ReadAll(directory / "owner.txt") == "vmap" ? std::string() : std::string("owner.txt does not say vmap");
  };
  policy.inputs = std::move(inputs);
  return policy;
}

void MakeOwned(const fs::path& directory) {
  fs::create_directories(directory);
  std::ofstream(directory / "owner.txt") << "vmap";
  std::ofstream(directory / "old.txt") << "old";
}

std::string RefusalOf(const fs::path& target, const OutputPolicy& policy) {
  try {
    AtomicOutputDirectory directory(target, policy);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// The pid of a process that has ended.
pid_t DeadPid() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  return child;
}

}  // namespace

TEST(AtomicOutput, DirectoryAppearsOnlyOnCommit) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  {
    AtomicOutputDirectory dir(target, MarkerPolicy());
    std::ofstream(dir.path() / "a.txt") << "hello";
    EXPECT_FALSE(fs::exists(target));
    dir.Commit();
  }
  EXPECT_EQ(ReadAll(target / "a.txt"), "hello");
  EXPECT_EQ(CountEntries(tmp.path()), 1);
}

TEST(AtomicOutput, UncommittedDirectoryLeavesNothingAndKeepsTheOldOne) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  MakeOwned(target);
  {
    AtomicOutputDirectory dir(target, MarkerPolicy());
    std::ofstream(dir.path() / "new.txt") << "new";
    // destroyed without Commit: as if the build failed half-way
  }
  EXPECT_TRUE(fs::exists(target / "old.txt"));
  EXPECT_FALSE(fs::exists(target / "new.txt"));
  EXPECT_EQ(CountEntries(tmp.path()), 1);
}

TEST(AtomicOutput, AnUncommittedDirectoryTakesTheFoldersCreatedForItWithIt) {
  testing::ScopedTempDir tmp;
  // Neither runs/ nor runs/today/ exists: a failed output leaves neither behind.
  { AtomicOutputDirectory dir(tmp.path() / "runs" / "today" / "map", MarkerPolicy()); }
  EXPECT_EQ(CountEntries(tmp.path()), 0);
  // A folder that existed stays, and so does one something else wrote into meanwhile.
  fs::create_directory(tmp.path() / "runs");
  {
    AtomicOutputDirectory dir(tmp.path() / "runs" / "today" / "map", MarkerPolicy());
    std::ofstream(tmp.path() / "runs" / "today" / "notes.txt") << "not vmap's";
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "runs" / "today" / "notes.txt"));
  EXPECT_EQ(CountEntries(tmp.path() / "runs" / "today"), 1);
  fs::remove_all(tmp.path() / "runs" / "today");
  { AtomicOutputDirectory dir(tmp.path() / "runs" / "today" / "map", MarkerPolicy()); }
  EXPECT_TRUE(fs::exists(tmp.path() / "runs"));
  EXPECT_EQ(CountEntries(tmp.path() / "runs"), 0);
  // "ghost/../map": creating its parent made ghost/, which goes too.
  fs::remove_all(tmp.path() / "runs");
  { AtomicOutputDirectory dir(tmp.path() / "ghost" / ".." / "map", MarkerPolicy()); }
  EXPECT_EQ(CountEntries(tmp.path()), 0);
  // Committed, they are the output's.
  {
    AtomicOutputDirectory dir(tmp.path() / "new" / "map", MarkerPolicy());
    dir.Commit();
  }
  EXPECT_TRUE(fs::is_directory(tmp.path() / "new" / "map"));
}

TEST(AtomicOutput, CommitReplacesAnOlderDirectoryAndLeavesNothingElse) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  MakeOwned(target);
  AtomicOutputDirectory dir(target, MarkerPolicy());
  std::ofstream(dir.path() / "new.txt") << "new";
  dir.Commit();
  EXPECT_FALSE(fs::exists(target / "old.txt"));
  EXPECT_EQ(ReadAll(target / "new.txt"), "new");
  EXPECT_EQ(CountEntries(tmp.path()), 1) << "the old directory is removed";
}

// A rebuild keeps what it did not write: the replaced directory's entries that are not the output's own move into the
// new one, where it holds none of that name; its own go with it.
TEST(AtomicOutput, ReplacingADirectoryKeepsWhatItHeldBesidesTheOutputsOwnFiles) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  MakeOwned(target);  // owner.txt, old.txt
  std::ofstream(target / "notes.txt") << "the user's";
  std::ofstream(target / "both.txt") << "old";
  fs::create_directory(target / "runs");
  std::ofstream(target / "runs" / "a.csv") << "a run";
  OutputPolicy policy = MarkerPolicy();
  policy.is_own_entry = [](const std::string& name) { return name == "owner.txt" || name == "old.txt"; };
  {
    AtomicOutputDirectory dir(target, policy);
    std::ofstream(dir.path() / "owner.txt") << "vmap";
    std::ofstream(dir.path() / "both.txt") << "new";
    dir.Commit();
  }
  EXPECT_EQ(ReadAll(target / "notes.txt"), "the user's");
  EXPECT_EQ(ReadAll(target / "runs" / "a.csv"), "a run");
  EXPECT_EQ(ReadAll(target / "both.txt"), "new") << "the new output's file of that name wins";
  EXPECT_FALSE(fs::exists(target / "old.txt")) << "the output's own entries go with the replaced one";
  EXPECT_EQ(CountEntries(target), 4);
  EXPECT_EQ(CountEntries(tmp.path()), 1) << "nothing left beside it";
  // Without the policy's say, the replaced directory goes whole, as before.
  {
    AtomicOutputDirectory dir(target, MarkerPolicy());
    std::ofstream(dir.path() / "owner.txt") << "vmap";
    dir.Commit();
  }
  EXPECT_EQ(CountEntries(target), 1);
}

// `vmap build X -o .` in an empty folder replaced the folder the shell was in: its `ls` showed nothing after.
TEST(AtomicOutput, NeverReplacesTheFolderItRunsInNorOneHoldingIt) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  fs::create_directories(target / "sub");
  const fs::path before = fs::current_path();
  for (const fs::path& here : {target, target / "sub"}) {
    fs::current_path(here);
    const std::string refusal = RefusalOf(target, MarkerPolicy());
    fs::current_path(before);
    EXPECT_NE(refusal.find("is or holds the folder vmap runs in"), std::string::npos) << here << ": " << refusal;
  }
  EXPECT_EQ(RefusalOf(target, MarkerPolicy()).find("runs in"), std::string::npos);
}

TEST(AtomicOutput, RefusesToReplaceAFileOrASymbolicLink) {
  testing::ScopedTempDir tmp;
  std::ofstream(tmp.path() / "file") << "x";
  EXPECT_NE(RefusalOf(tmp.path() / "file", MarkerPolicy()).find("not a directory"), std::string::npos);
  MakeOwned(tmp.path() / "owned");
  fs::create_directory_symlink(tmp.path() / "owned", tmp.path() / "link");
  EXPECT_NE(RefusalOf(tmp.path() / "link", MarkerPolicy()).find("symbolic link"), std::string::npos);
  EXPECT_EQ(ReadAll(tmp.path() / "file"), "x");
  EXPECT_EQ(ReadAll(tmp.path() / "owned/old.txt"), "old");
}

TEST(AtomicOutput, NeverReplacesADirectoryItCannotProveItsOwn) {
  testing::ScopedTempDir tmp;
  const fs::path documents = tmp.path() / "documents";
  fs::create_directories(documents / ".git");
  std::ofstream(documents / "thesis.tex") << "precious";
  // No proof file, a proof that says otherwise, and no proof function at all (only empty folders then).
  const std::string refusal = RefusalOf(documents, MarkerPolicy());
  EXPECT_NE(refusal.find("will not replace it"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("owner.txt does not say vmap"), std::string::npos) << refusal;
  std::ofstream(documents / "owner.txt") << "someone else";
  EXPECT_NE(RefusalOf(documents, MarkerPolicy()), "");
  std::ofstream(documents / "owner.txt") << "vmap";
  EXPECT_NE(RefusalOf(documents, OutputPolicy{}).find("not empty"), std::string::npos);
  EXPECT_EQ(ReadAll(documents / "thesis.tex"), "precious");
  EXPECT_TRUE(fs::is_directory(documents / ".git"));
  // An empty directory may be used, by any policy.
  fs::create_directories(tmp.path() / "empty");
  AtomicOutputDirectory empty(tmp.path() / "empty", OutputPolicy{});
  empty.Commit();
}

TEST(AtomicOutput, AnOutputThatCannotBePlacedIsKeptWhenThePolicySaysSo) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  OutputPolicy policy = MarkerPolicy();
  policy.keep_if_commit_fails = true;
  std::string error;
  {
    AtomicOutputDirectory dir(target, policy);
    std::ofstream(dir.path() / "map.json") << "finished";
    // While vmap worked, a folder of someone else's appeared where the output goes.
    fs::create_directories(target);
    std::ofstream(target / "notes.txt") << "mine";
    try {
      dir.Commit();
    } catch (const InputError& e) {
      error = e.what();
    }
  }
  EXPECT_EQ(ReadAll(target / "notes.txt"), "mine");
  const size_t at = error.find("the finished output is kept at '");
  ASSERT_NE(at, std::string::npos) << error;
  const std::string kept = error.substr(at + 32, error.find('\'', at + 32) - at - 32);
  EXPECT_NE(kept.find("map.unplaced-"), std::string::npos) << kept;
  EXPECT_EQ(ReadAll(fs::path(kept) / "map.json"), "finished");
  // Neither the object's end nor a later run's clean-up of dead processes' temporaries removes it.
  RemoveStaleTemporaries(target);
  EXPECT_TRUE(fs::exists(fs::path(kept) / "map.json"));
}

TEST(AtomicOutput, TheProofIsCheckedAgainWhenCommitting) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  MakeOwned(target);
  AtomicOutputDirectory dir(target, MarkerPolicy());
  // While vmap worked, the folder became someone else's.
  std::ofstream(target / "owner.txt") << "user";
  std::ofstream(target / "notes.txt") << "mine";
  EXPECT_THROW(dir.Commit(), InputError);
  EXPECT_EQ(ReadAll(target / "notes.txt"), "mine");
  // The same for a folder that appears while vmap works.
  AtomicOutputDirectory fresh(tmp.path() / "fresh", MarkerPolicy());
  fs::create_directories(tmp.path() / "fresh");
  std::ofstream(tmp.path() / "fresh/notes.txt") << "mine";
  EXPECT_THROW(fresh.Commit(), InputError);
  EXPECT_EQ(ReadAll(tmp.path() / "fresh/notes.txt"), "mine");
}

TEST(AtomicOutput, NeverReplacesItsInputNorWritesIntoIt) {
  testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  MakeOwned(map);
  fs::create_directories(map / "keys");
  std::ofstream(map / "keys/000000.png") << "image";
  fs::create_directories(tmp.path() / "sequence");
  fs::create_directory_symlink(map / "keys", tmp.path() / "keys_link");
  struct Case {
    fs::path output, input;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {map, map, "is or holds the input"},                                  // the same folder
      {map, map / "keys", "is or holds the input"},                         // the input inside
      {map, map / "keys/000000.png", "is or holds the input"},              // a file inside
      {map, tmp.path() / "keys_link", "is or holds the input"},             // through a symbolic link
      {map, tmp.path() / "sequence/../map/keys", "is or holds the input"},  // through ".."
      {tmp.path() / "sequence/out", tmp.path() / "sequence", "lies inside the input"},
      {map / "keys/new", map, "lies inside the input"},
  };
  for (const Case& c : cases) {
    const std::string refusal = RefusalOf(c.output, MarkerPolicy({c.input}));
    EXPECT_NE(refusal.find(c.expected), std::string::npos) << c.output << " <- " << c.input << ": " << refusal;
  }
  EXPECT_EQ(ReadAll(map / "keys/000000.png"), "image");
  // An unrelated input is fine.
  AtomicOutputDirectory elsewhere(map, MarkerPolicy({tmp.path() / "sequence"}));
  elsewhere.Commit();
}

TEST(AtomicOutput, StaleTemporariesOfDeadProcessesAreRemovedAndLiveOnesKept) {
  testing::ScopedTempDir tmp;
  const std::string dead = std::to_string(DeadPid()), alive = std::to_string(getpid());
  const std::vector<std::string> stale = {".map.partial-" + dead + "-12", ".map.old-" + dead + "-3",
                                          ".map.tmp-" + dead + "-4"};
  const std::vector<std::string> kept = {".map.partial-" + alive + "-5",   // this process: alive
                                         ".map.partial-1-6",               // init: alive
                                         ".other.partial-" + dead + "-7",  // another output's
                                         ".map.partial-" + dead + "-x",    // not vmap's pattern
                                         ".map.backup-" + dead + "-8",
                                         "map.partial-" + dead + "-9"};
  for (const std::string& name : stale) {
    fs::create_directories(tmp.path() / name / "keys");
    std::ofstream(tmp.path() / name / "keys/a.png") << "x";
  }
  for (const std::string& name : kept) fs::create_directories(tmp.path() / name);
  AtomicOutputDirectory dir(tmp.path() / "map", MarkerPolicy());
  for (const std::string& name : stale) EXPECT_FALSE(fs::exists(tmp.path() / name)) << name;
  for (const std::string& name : kept) EXPECT_TRUE(fs::exists(tmp.path() / name)) << name;

  // WriteFileAtomically does the same for its ".NAME.tmp-PID-N" files.
  std::ofstream(tmp.path() / (".f.json.tmp-" + dead + "-1")) << "half";
  std::ofstream(tmp.path() / (".f.json.tmp-" + alive + "-2")) << "being written";
  WriteFileAtomically(tmp.path() / "f.json", "{}");
  EXPECT_FALSE(fs::exists(tmp.path() / (".f.json.tmp-" + dead + "-1")));
  EXPECT_TRUE(fs::exists(tmp.path() / (".f.json.tmp-" + alive + "-2")));
}

TEST(AtomicOutput, WriteFileAtomicallyWritesContentAndNoTemporaries) {
  testing::ScopedTempDir tmp;
  WriteFileAtomically(tmp.path() / "f.json", "{\"a\": 1}");
  EXPECT_EQ(ReadAll(tmp.path() / "f.json"), "{\"a\": 1}");
  WriteFileAtomically(tmp.path() / "f.json", "{\"a\": 2}");
  EXPECT_EQ(ReadAll(tmp.path() / "f.json"), "{\"a\": 2}");
  EXPECT_EQ(CountEntries(tmp.path()), 1);
  EXPECT_THROW(WriteFileAtomically(tmp.path() / "missing_dir" / "f.json", "x"), InputError);
  fs::create_directories(tmp.path() / "folder/inside");
  EXPECT_THROW(WriteFileAtomically(tmp.path() / "folder", "x"), InputError);
  EXPECT_TRUE(fs::is_directory(tmp.path() / "folder/inside"));
  EXPECT_EQ(CountEntries(tmp.path()), 2);
  // A name the system takes but its temporary's is too long for: said so, with the length that works.
  const std::string long_name(245, 'n');
  for (const auto& write :
       std::vector<std::function<void()>>{[&] { WriteFileAtomically(tmp.path() / (long_name + ".json"), "x"); },
                                          [&] { AtomicOutputDirectory(tmp.path() / long_name, OutputPolicy{}); }}) {
    try {
      write();
      ADD_FAILURE() << "a name too long for its temporary was written";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("at most 230 bytes"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(CountEntries(tmp.path()), 2);
  // A private file stays private when replaced.
  fs::permissions(tmp.path() / "f.json", fs::perms::owner_read | fs::perms::owner_write);
  WriteFileAtomically(tmp.path() / "f.json", "{\"a\": 3}");
  EXPECT_EQ(ReadAll(tmp.path() / "f.json"), "{\"a\": 3}");
  EXPECT_EQ(fs::status(tmp.path() / "f.json").permissions(), fs::perms::owner_read | fs::perms::owner_write);
}

TEST(AtomicOutputDeathTest, RemovingTemporariesForExitTakesEveryUnfinishedOutput) {
  testing::ScopedTempDir tmp;
  const fs::path target = tmp.path() / "map";
  MakeOwned(target);
  // In a child process: the registry stays locked afterwards, as for a process about to end.
  EXPECT_EXIT(
      {
        AtomicOutputDirectory dir(target, MarkerPolicy());
        std::ofstream(dir.path() / "half.txt") << "half";
        AtomicOutputDirectory other(tmp.path() / "other", MarkerPolicy());
        const int removed = RemoveTemporaryOutputsForExit();
        _exit(removed == 2 && !fs::exists(dir.path()) && !fs::exists(other.path()) ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
  EXPECT_EQ(CountEntries(tmp.path()), 1);
  EXPECT_EQ(ReadAll(target / "old.txt"), "old");
}

}  // namespace vmap
