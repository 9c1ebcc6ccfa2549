#include "vmap/core/runtime.h"

#include <malloc.h>

#include <cstdlib>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "vmap/core/error.h"

extern "C" {
#include <libavutil/log.h>
}

namespace vmap {
namespace {

RuntimeOptions Nothing() {
  RuntimeOptions options;
  options.opencv_threads = 0;
  options.keep_freed_memory = false;
  options.quiet_ffmpeg = false;
  options.handle_interrupts = false;
  return options;
}

// Whether a block of `bytes` comes from a mmap() of its own (glibc counts those in hblks).
bool AllocationIsMapped(size_t bytes) {
  const size_t before = mallinfo2().hblks;
  void* volatile block = std::malloc(bytes);
  const size_t during = mallinfo2().hblks;
  std::free(block);
  return during > before;
}

}  // namespace

TEST(RuntimeOptions, CheckNamesTheBadField) {
  RuntimeOptions options;
  EXPECT_NO_THROW(options.Check());
  options.opencv_threads = -2;
  try {
    options.Check();
    FAIL() << "negative thread count accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("opencv_threads -2 is outside [0, 256]"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(InitializeRuntime(options), InputError);
  options.opencv_threads = 100000;  // a pool that large crashed the Python module at exit
  EXPECT_THROW(options.Check(), InputError);
}

TEST(Runtime, SetsOpenCvThreads) {
  const int before = cv::getNumThreads();
  RuntimeOptions options = Nothing();
  options.opencv_threads = 3;
  InitializeRuntime(options);
  EXPECT_EQ(cv::getNumThreads(), 3);
  options.opencv_threads = 0;  // leaves it
  InitializeRuntime(options);
  EXPECT_EQ(cv::getNumThreads(), 3);
  cv::setNumThreads(before);
}

TEST(Runtime, KeepsLargeFreedBlocksInTheHeap) {
  // Above glibc's largest dynamic mmap threshold (32 MiB), and larger than all the heap's free memory (fordblks),
  // which earlier tests in this process may have left there (a whole-binary run): no free chunk can serve it, so
  // only the mmap settings decide whether it is a mmap of its own.
  const size_t kLarge = mallinfo2().fordblks + (size_t(64) << 20);
  mallopt(M_MMAP_MAX, 65536);  // glibc's default
  EXPECT_TRUE(AllocationIsMapped(kLarge)) << "the control: by default such a block is a mmap of its own";
  InitializeRuntime(Nothing());
  EXPECT_TRUE(AllocationIsMapped(kLarge)) << "keep_freed_memory off changes nothing";
  RuntimeOptions options = Nothing();
  options.keep_freed_memory = true;
  InitializeRuntime(options);
  EXPECT_FALSE(AllocationIsMapped(kLarge));
  // Give the process back glibc's settings and the freed block: with the trim threshold left at 1 GiB the freed block
  // stays in the heap, and the control above fails when the test runs again in this process (--gtest_repeat).
  mallopt(M_MMAP_MAX, 65536);
  mallopt(M_TRIM_THRESHOLD, 128 * 1024);
  malloc_trim(0);
}

TEST(Runtime, QuietsFfmpeg) {
  av_log_set_level(AV_LOG_INFO);
  InitializeRuntime(Nothing());
  EXPECT_EQ(av_log_get_level(), AV_LOG_INFO);
  RuntimeOptions options = Nothing();
  options.quiet_ffmpeg = true;
  InitializeRuntime(options);
  EXPECT_EQ(av_log_get_level(), AV_LOG_QUIET);
}

}  // namespace vmap
