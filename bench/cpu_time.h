#pragma once
// CPU time for the benchmarks: the machine is shared and its speed drifts, so the benchmarks compare CPU
// seconds measured side by side rather than wall time.

#include <time.h>

namespace vmap::bench {

// User and system time of all the process's threads.
inline double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The calling thread's alone.
inline double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace vmap::bench
