#include "vmap/core/serial_worker.h"

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace vmap {
namespace {

TEST(SerialWorker, RunsJobsInOrderOffTheCallersThread) {
  SerialWorker worker;
  std::vector<int> order;  // written by the worker only, read after Wait()
  std::vector<std::thread::id> threads;
  for (int i = 0; i < 100; ++i) {
    worker.Post([&, i] {
      order.push_back(i);
      threads.push_back(std::this_thread::get_id());
    });
  }
  worker.Wait();
  ASSERT_EQ(order.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(order[i], i);
  for (const auto& id : threads) EXPECT_NE(id, std::this_thread::get_id());
}

TEST(SerialWorker, WaitRethrowsTheFirstErrorAndSkipsTheJobsAfterIt) {
  SerialWorker worker;
  std::atomic<int> ran{0};
  worker.Post([&] { ++ran; });
  worker.Post([] { throw std::runtime_error("first"); });
  worker.Post([] { throw std::runtime_error("second"); });
  worker.Post([&] { ++ran; });
  try {
    worker.Wait();
    FAIL() << "Wait() must rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "first");
  }
  EXPECT_EQ(ran.load(), 1);
  EXPECT_THROW(worker.Wait(), std::runtime_error) << "the error stays";
}

TEST(SerialWorker, DestructorRunsWhatIsStillQueued) {
  std::atomic<int> ran{0};
  {
    SerialWorker worker;
    worker.Post([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ++ran;
    });
    for (int i = 0; i < 9; ++i) worker.Post([&] { ++ran; });
  }
  EXPECT_EQ(ran.load(), 10);
}

}  // namespace
}  // namespace vmap
