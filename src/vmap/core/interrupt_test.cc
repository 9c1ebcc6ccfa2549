#include "vmap/core/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/atomic_output.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

long CountEntries(const fs::path& directory) {
  return std::distance(fs::directory_iterator(directory), fs::directory_iterator());
}

// Signal dispositions as a command started from a terminal has them, whatever this test runner inherited (a
// shell starts background jobs with SIGINT ignored); and a deadline, so that a failure cannot hang the test.
void StartAsFromATerminal() {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) signal(signal_number, SIG_DFL);
  alarm(20);
}

// In the child process of a death test: start writing an output, then receive `signal_number` from outside
// (kill(), as a shell or a service manager sends it) and wait to be ended.
[[noreturn]] void WriteAndReceive(const fs::path& target, int signal_number) {
  StartAsFromATerminal();
  InstallInterruptHandling();
  AtomicOutputDirectory directory(target, OutputPolicy{});
  std::ofstream(directory.path() / "half.txt") << "half";
  WriteFileAtomically(target.parent_path() / "done.txt", "finished before the signal");
  kill(getpid(), signal_number);
  for (;;) pause();
}

}  // namespace

// Death tests fork this process: each runs its statement in a child, so the signal handling installed there
// never touches the test runner.
TEST(InterruptDeathTest, SigintRemovesTheUnfinishedOutputAndExitsWith130) {
  testing::ScopedTempDir tmp;
  EXPECT_EXIT(WriteAndReceive(tmp.path() / "map", SIGINT), ::testing::ExitedWithCode(128 + SIGINT), "interrupted");
  EXPECT_EQ(CountEntries(tmp.path()), 1) << "only the finished file remains";
  EXPECT_TRUE(fs::exists(tmp.path() / "done.txt"));
}

TEST(InterruptDeathTest, SigtermAndSighupDoTheSame) {
  for (int signal_number : {SIGTERM, SIGHUP}) {
    testing::ScopedTempDir tmp;
    EXPECT_EXIT(WriteAndReceive(tmp.path() / "map", signal_number), ::testing::ExitedWithCode(128 + signal_number),
                "interrupted");
    EXPECT_EQ(CountEntries(tmp.path()), 1) << strsignal(signal_number);
  }
}

TEST(InterruptDeathTest, ASignalIgnoredAtStartStaysIgnored) {
  testing::ScopedTempDir tmp;
  // As under nohup: SIGHUP ignored before vmap starts.
  EXPECT_EXIT(
      {
        StartAsFromATerminal();
        signal(SIGHUP, SIG_IGN);
        InstallInterruptHandling();
        kill(getpid(), SIGHUP);
        usleep(200000);
        _exit(7);
      },
      ::testing::ExitedWithCode(7), "");
}

TEST(InterruptDeathTest, NothingIsRemovedAfterACommit) {
  testing::ScopedTempDir tmp;
  EXPECT_EXIT(
      {
        StartAsFromATerminal();
        InstallInterruptHandling();
        AtomicOutputDirectory directory(tmp.path() / "map", OutputPolicy{});
        std::ofstream(directory.path() / "complete.txt") << "complete";
        directory.Commit();
        kill(getpid(), SIGTERM);
        for (;;) pause();
      },
      ::testing::ExitedWithCode(128 + SIGTERM), "");
  EXPECT_TRUE(fs::exists(tmp.path() / "map/complete.txt"));
  EXPECT_EQ(CountEntries(tmp.path()), 1);
}

}  // namespace vmap

namespace vmap {
namespace {

// In the child of a death test: with the graceful SIGINT on, a first SIGINT only asks the input to end (the
// process goes on, its outputs intact), a second one aborts as usual.
[[noreturn]] void EndInputThenAbort(const fs::path& target) {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) signal(signal_number, SIG_DFL);
  alarm(20);
  InstallInterruptHandling();
  EndInputOnSigint(true);
  AtomicOutputDirectory directory(target, OutputPolicy{});
  if (InputEndRequested()) _exit(3);
  kill(getpid(), SIGINT);
  while (!InputEndRequested()) usleep(1000);
  if (!fs::exists(directory.path())) _exit(4);  // the first SIGINT removed nothing
  kill(getpid(), SIGINT);
  for (;;) pause();
}

}  // namespace

TEST(InterruptDeathTest, WithEndInputOnSigintTheFirstSigintEndsTheInputAndASecondAborts) {
  testing::ScopedTempDir tmp;
  EXPECT_EXIT(EndInputThenAbort(tmp.path() / "map"), ::testing::ExitedWithCode(128 + SIGINT),
              "finishing the map from the frames seen(.|\n)*interrupted");
  EXPECT_EQ(CountEntries(tmp.path()), 0) << "the second SIGINT removed the unfinished output";
}

}  // namespace vmap
