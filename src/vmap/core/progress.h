#pragma once
// A one-line progress display (done/total, items per second, ETA) for long work. It draws only on
// an interactive terminal, so logs and pipes stay clean.

#include <chrono>
#include <cstdio>
#include <string>

namespace vmap {

struct ProgressOptions {
  bool enabled = true;  // false for --quiet
  bool force = false;   // draw even when stderr is not a terminal (tests)
  double min_interval_s = 0.2;
};

class ProgressLine {
 public:
  // `total` may be 0 when unknown (no ETA then).
  ProgressLine(std::string label, long total, std::string unit, ProgressOptions options = {},
               std::FILE* stream = stderr);
  ~ProgressLine();

  void Update(long done);
  // Clears the line so that the next output starts on a clean line.
  void Finish();

  // "12.5 frames/s, ETA 1m05s" style text for the given state; exposed for tests.
  static std::string Format(const std::string& label, long done, long total, const std::string& unit, double elapsed_s);

 private:
  std::string label_;
  long total_;
  std::string unit_;
  std::FILE* stream_;
  bool active_;
  double min_interval_s_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  bool drawn_ = false;
};

}  // namespace vmap
