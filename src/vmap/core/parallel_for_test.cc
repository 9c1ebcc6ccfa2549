#include "vmap/core/parallel_for.h"

#include <atomic>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace vmap {
namespace {

TEST(ParallelFor, EveryJobRunsOnceOnTheThreadsAsked) {
  for (int threads : {1, 3}) {
    std::vector<std::atomic<int>> runs(100);
    std::mutex mutex;
    std::set<std::thread::id> ids;
    ParallelFor(runs.size(), threads, [&](size_t i) {
      ++runs[i];
      std::this_thread::sleep_for(std::chrono::microseconds(200));  // long enough for every thread to take some
      std::lock_guard<std::mutex> lock(mutex);
      ids.insert(std::this_thread::get_id());
    });
    for (size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i], 1) << i;
    EXPECT_LE(ids.size(), static_cast<size_t>(threads));
    EXPECT_TRUE(ids.count(std::this_thread::get_id())) << "the caller's thread works too";
  }
  ParallelFor(0, 4, [](size_t) { FAIL() << "no job to run"; });
}

TEST(ParallelFor, AJobsExceptionReachesTheCallerAndNoNewJobStarts) {
  std::atomic<int> started{0};
  EXPECT_THROW(ParallelFor(1000, 1,
                           [&](size_t i) {
                             ++started;
                             if (i == 10) throw std::runtime_error("job 10");
                           }),
               std::runtime_error);
  EXPECT_EQ(started, 11);
}

}  // namespace
}  // namespace vmap
