#pragma once
// Runs jobs one after another, in the order they were posted, on a thread of its own: for work that must
// leave the caller's thread but keep its order (key images written to disk, links verified in full while the
// build goes on).

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace vmap {

class SerialWorker {
 public:
  SerialWorker();
  // Runs the jobs still queued, then joins. Their errors are dropped: call Wait() to see them.
  ~SerialWorker();
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  void Post(std::function<void()> job);

  // Waits until every job posted so far has run. Rethrows the first exception a job threw; the jobs after it
  // are skipped, as their work would build on a failed one.
  void Wait();

 private:
  void Run();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> queue_;
  bool busy_ = false;
  bool finished_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: starts after every other member exists
};

}  // namespace vmap
