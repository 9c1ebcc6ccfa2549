#pragma once
// Hands camera messages from ROS's callback threads to the node's worker without ever making a callback wait:
// a mailbox of `capacity` items where a new item pushes out the oldest when it is full, and counts it as dropped.
// With capacity 1 the worker always takes the newest frame (repeat: a slow frame is never followed by a queue of
// stale ones, the robot steers by what it sees now); a larger capacity rides out a slow moment without losing
// frames (teach: every frame counts towards the map).

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace vmap::ros_node {

template <typename T>
class Mailbox {
 public:
  explicit Mailbox(size_t capacity = 1) : capacity_(capacity > 0 ? capacity : 1) {}

  // Never waits. Returns false, dropping `item`, when the mailbox is closed.
  bool Put(T item) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_) return false;
      items_.push_back(std::move(item));
      while (items_.size() > capacity_) {
        items_.pop_front();
        ++dropped_;
      }
    }
    changed_.notify_one();
    return true;
  }

  // The oldest item held, waiting up to `timeout` for one; nullopt after the timeout, or once the mailbox is closed
  // and empty.
  std::optional<T> Take(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, timeout, [this] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    return item;
  }

  // Items pushed out since the last call.
  size_t TakeDropped() {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t dropped = dropped_;
    dropped_ = 0;
    return dropped;
  }

  // Empties the mailbox and sets its capacity (dropped items are not counted: the caller changed its mind).
  void Reset(size_t capacity) {
    std::lock_guard<std::mutex> lock(mutex_);
    items_.clear();
    dropped_ = 0;
    capacity_ = capacity > 0 ? capacity : 1;
  }

  // No more items: Put refuses them, Take hands out those held, then nullopt at once.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    changed_.notify_all();
  }

  bool closed_and_empty() {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_ && items_.empty();
  }

 private:
  size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<T> items_;
  size_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace vmap::ros_node
