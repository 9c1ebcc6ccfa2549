#include "vmap/core/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace vmap {

void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& job) {
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto run = [&] {
    try {
      for (size_t i = next++; i < count; i = next++) job(i);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next = count;
    }
  };
  const size_t helpers = std::min<size_t>(static_cast<size_t>(std::max(threads, 1)), std::max<size_t>(count, 1)) - 1;
  std::vector<std::thread> workers;
  try {
    for (size_t k = 0; k < helpers; ++k) workers.emplace_back(run);
  } catch (...) {  // a thread that cannot start (the process limit): the ones started end before the error goes on
    next = count;
    for (std::thread& worker : workers) worker.join();
    throw;
  }
  run();
  for (std::thread& worker : workers) worker.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace vmap
