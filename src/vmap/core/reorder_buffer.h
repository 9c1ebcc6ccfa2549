#pragma once
// Results that worker threads finish out of order, handed out in order: item k is put by whichever worker made
// it and taken by the one consumer as the k-th. A failure ends it: Take and TryTake rethrow it from then on.

#include <condition_variable>
#include <exception>
#include <map>
#include <mutex>
#include <optional>

namespace vmap {

template <typename T>
class ReorderBuffer {
 public:
  // Item number `sequence` is done (each number once).
  void Put(long sequence, T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    items_.emplace(sequence, std::move(item));
    changed_.notify_all();
  }

  // A worker failed: the consumer gets `error` instead of any item, now or at its next call. The first wins.
  void Fail(std::exception_ptr error) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = std::move(error);
    changed_.notify_all();
  }

  // Waits for item `sequence` and takes it out. Only wait for an item a worker will put (or fail).
  T Take(long sequence) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return error_ || items_.count(sequence); });
    return TakeLocked(sequence).value();
  }

  // Item `sequence` if it is done, otherwise nullopt.
  std::optional<T> TryTake(long sequence) {
    std::lock_guard<std::mutex> lock(mutex_);
    return TakeLocked(sequence);
  }

  void RethrowIfFailed() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::optional<T> TakeLocked(long sequence) {
    if (error_) std::rethrow_exception(error_);
    const auto found = items_.find(sequence);
    if (found == items_.end()) return std::nullopt;
    T item = std::move(found->second);
    items_.erase(found);
    return item;
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<long, T> items_;
  std::exception_ptr error_;
};

}  // namespace vmap
