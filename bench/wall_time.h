#pragma once
// Wall time for the benchmarks that time one call at a time (the LibTorch matchers' aliked_bench, xfeat_bench and
// loftr_bench); cpu_time.h for CPU time.

#include <chrono>

namespace vmap::bench {

// The wall seconds `f()` takes.
template <typename F>
double TimeSeconds(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace vmap::bench
