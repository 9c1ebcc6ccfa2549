#pragma once
// Work done on worker threads ahead of one consumer, which gets the results in the order it handed the items
// over: the read-ahead/extract-ahead of both building (mapping/feature_pipeline.h) and localization
// (localization/localize_sequence.cc). The consumer hands items over (TryPush) and takes results (Next,
// TryNext) on its own thread; `workers` threads run `work` on the items meanwhile. At most `depth` items are in
// flight (handed over, not taken out), so memory does not grow with the input. A worker's error stops the
// pipeline and reaches the consumer at its next call.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "vmap/core/bounded_queue.h"
#include "vmap/core/error.h"
#include "vmap/core/reorder_buffer.h"

namespace vmap {

template <typename In, typename Out>
class OrderedPipeline {
 public:
  using WorkFn = std::function<Out(In item)>;

  // Starts the workers; `work` runs on them, for one item at a time each. Throws InputError when the system
  // refuses a thread (a process limit).
  OrderedPipeline(int depth, int workers, WorkFn work)
      : work_(std::move(work)), depth_(std::max(depth, 1)), to_do_(static_cast<size_t>(depth_)) {
    try {
      for (int i = 0; i < workers; ++i) workers_.emplace_back([this] { Work(); });
    } catch (const std::system_error& error) {
      Stop();  // the threads already started, or their destructors abort
      throw InputError("cannot start " + std::to_string(workers) + " threads (" + error.what() +
                       "); use fewer extraction threads");
    }
  }

  ~OrderedPipeline() { Stop(); }
  OrderedPipeline(const OrderedPipeline&) = delete;
  OrderedPipeline& operator=(const OrderedPipeline&) = delete;

  // Hands `item` to the workers, unless `depth` items are in flight already: then false, and `item` is left as
  // it was (take a result out with Next() first). Rethrows a worker's error.
  bool TryPush(In& item) {
    done_.RethrowIfFailed();
    if (closed_) throw std::logic_error("OrderedPipeline::TryPush after Close");
    if (pushed_ - taken_ >= depth_) return false;
    // Never waits: the queue holds at most the items in flight, no more than its capacity.
    to_do_.Push({pushed_++, std::move(item)});
    return true;
  }

  // No more items: Next() returns nullopt once every result has come out.
  void Close() {
    closed_ = true;
    to_do_.Close();
  }

  // The next result in order, waiting for it; nullopt at the end (after Close). Rethrows a worker's error.
  std::optional<Out> Next() {
    if (taken_ == pushed_) {
      if (closed_) return std::nullopt;
      throw std::logic_error("OrderedPipeline::Next with no item in flight");
    }
    Out result = done_.Take(taken_);
    ++taken_;
    return result;
  }

  // The next result when it is ready now, otherwise nullopt. Rethrows a worker's error.
  std::optional<Out> TryNext() {
    if (taken_ == pushed_) return std::nullopt;
    std::optional<Out> result = done_.TryTake(taken_);
    if (result) ++taken_;
    return result;
  }

  long taken() const { return taken_; }  // results taken out so far
  int depth() const { return depth_; }

 private:
  void Stop() {
    stop_ = true;
    to_do_.Close();
    for (std::thread& worker : workers_) worker.join();
  }

  // A worker: items until the queue closes; an error stops the pipeline and reaches the consumer.
  void Work() {
    while (std::optional<std::pair<long, In>> item = to_do_.Pop()) {
      if (stop_) continue;  // stopping: drain without work
      try {
        done_.Put(item->first, work_(std::move(item->second)));
      } catch (...) {
        stop_ = true;
        done_.Fail(std::current_exception());
        to_do_.Close();
      }
    }
  }

  const WorkFn work_;
  const int depth_;
  // The consumer's side: items handed over and results taken out (in flight: the difference).
  long pushed_ = 0;
  long taken_ = 0;
  bool closed_ = false;
  BoundedQueue<std::pair<long, In>> to_do_;  // items waiting for a worker, numbered
  ReorderBuffer<Out> done_;                  // results, by number
  std::atomic<bool> stop_{false};
  std::vector<std::thread> workers_;  // last: started once everything they use exists
};

}  // namespace vmap
