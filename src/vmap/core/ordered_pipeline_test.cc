#include "vmap/core/ordered_pipeline.h"

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace vmap {
namespace {

// Items that take longer the earlier they come finish out of order on four workers; they come out in order.
TEST(OrderedPipeline, ResultsComeOutInTheOrderTheItemsWentIn) {
  constexpr int kItems = 40;
  OrderedPipeline<int, int> pipeline(6, 4, [](int item) {
    std::this_thread::sleep_for(std::chrono::microseconds(200 * ((kItems - item) % 7)));
    return 10 * item;
  });
  std::vector<int> out;
  for (int i = 0; i < kItems; ++i) {
    int item = i;
    while (!pipeline.TryPush(item)) out.push_back(pipeline.Next().value());
    while (std::optional<int> result = pipeline.TryNext()) out.push_back(*result);
  }
  pipeline.Close();
  while (std::optional<int> result = pipeline.Next()) out.push_back(*result);
  ASSERT_EQ(out.size(), static_cast<size_t>(kItems));
  for (int i = 0; i < kItems; ++i) EXPECT_EQ(out[i], 10 * i);
  EXPECT_EQ(pipeline.taken(), kItems);
}

// No more than `depth` items are in flight: the next one is refused, and left to the caller, until a result
// is taken out.
TEST(OrderedPipeline, RefusesItemsBeyondItsDepth) {
  std::atomic<int> started{0};
  OrderedPipeline<std::vector<int>, int> pipeline(3, 2, [&](std::vector<int> item) {
    ++started;
    return static_cast<int>(item.size());
  });
  for (int i = 0; i < 3; ++i) {
    std::vector<int> item(i + 1, 0);
    ASSERT_TRUE(pipeline.TryPush(item));
  }
  std::vector<int> refused = {1, 2, 3, 4};
  EXPECT_FALSE(pipeline.TryPush(refused));
  EXPECT_EQ(refused.size(), 4u);  // left as it was
  EXPECT_EQ(pipeline.Next().value(), 1);
  EXPECT_TRUE(pipeline.TryPush(refused));
  pipeline.Close();
  EXPECT_EQ(pipeline.Next().value(), 2);
  EXPECT_EQ(pipeline.Next().value(), 3);
  EXPECT_EQ(pipeline.Next().value(), 4);
  EXPECT_FALSE(pipeline.Next().has_value());
  EXPECT_EQ(started.load(), 4);
}

// A worker's error reaches the consumer instead of the results after it.
TEST(OrderedPipeline, AWorkersErrorReachesTheConsumer) {
  OrderedPipeline<int, int> pipeline(4, 2, [](int item) {
    if (item == 2) throw std::runtime_error("bad item");
    return item;
  });
  // The error reaches whichever call the consumer makes next: a later TryPush when the worker fails while items
  // are still being handed over, otherwise Next.
  EXPECT_THROW(
      {
        for (int i = 0; i < 4; ++i) ASSERT_TRUE(pipeline.TryPush(i));
        pipeline.Close();
        while (pipeline.Next()) {
        }
      },
      std::runtime_error);
}

TEST(OrderedPipeline, NextWithNothingInFlightIsAProgrammingError) {
  OrderedPipeline<int, int> pipeline(2, 1, [](int item) { return item; });
  EXPECT_FALSE(pipeline.TryNext().has_value());
  EXPECT_THROW(pipeline.Next(), std::logic_error);
  pipeline.Close();
  EXPECT_FALSE(pipeline.Next().has_value());
  int item = 1;
  EXPECT_THROW(pipeline.TryPush(item), std::logic_error);
}

}  // namespace
}  // namespace vmap
