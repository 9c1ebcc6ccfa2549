#pragma once
// Wall time as the runs report it (seconds a stage took, frames/s): a steady clock, never the time of day.

#include <chrono>

namespace vmap {

inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace vmap
