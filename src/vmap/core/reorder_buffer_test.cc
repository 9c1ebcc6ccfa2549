#include "vmap/core/reorder_buffer.h"

#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace vmap {
namespace {

TEST(ReorderBuffer, ItemsPutOutOfOrderComeOutInOrder) {
  ReorderBuffer<std::string> buffer;
  buffer.Put(2, "two");
  buffer.Put(0, "zero");
  EXPECT_EQ(buffer.Take(0), "zero");
  EXPECT_FALSE(buffer.TryTake(1).has_value());  // not done yet: two waits behind it
  buffer.Put(1, "one");
  EXPECT_EQ(buffer.TryTake(1).value(), "one");
  EXPECT_EQ(buffer.Take(2), "two");
  EXPECT_FALSE(buffer.TryTake(2).has_value());  // taken once
}

TEST(ReorderBuffer, TakeWaitsForTheWorkerThatMakesTheItem) {
  ReorderBuffer<int> buffer;
  std::vector<std::thread> workers;
  for (int k = 0; k < 8; ++k) workers.emplace_back([&buffer, k] { buffer.Put(7 - k, 10 * (7 - k)); });
  for (int k = 0; k < 8; ++k) EXPECT_EQ(buffer.Take(k), 10 * k);
  for (std::thread& worker : workers) worker.join();
}

TEST(ReorderBuffer, AFailureReachesTheWaitingConsumerAndEveryLaterCall) {
  ReorderBuffer<int> buffer;
  buffer.Put(1, 1);
  std::thread worker([&buffer] {
    try {
      throw std::runtime_error("worker failed on item 0");
    } catch (...) {
      buffer.Fail(std::current_exception());
    }
  });
  EXPECT_THROW(buffer.Take(0), std::runtime_error);  // waits until the failure arrives
  worker.join();
  EXPECT_THROW(buffer.TryTake(1), std::runtime_error);  // done items are not handed out after a failure
  EXPECT_THROW(buffer.RethrowIfFailed(), std::runtime_error);
  buffer.Fail(std::make_exception_ptr(std::logic_error("second")));
  try {
    buffer.Take(1);
    FAIL() << "Take must rethrow";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()), "worker failed on item 0");  // the first failure wins
  }
}

}  // namespace
}  // namespace vmap
