#pragma once
// Process-wide settings, made in one place by the program that hosts vmap.
//
// Some settings belong to the whole process, not to a stage: OpenCV's thread pool, glibc's malloc, FFmpeg's
// log level and signal handling. The library never changes them on its own: a program that embeds vmap (a
// robot's node, a Python module) keeps its own. Every host that wants vmap's settings calls
// InitializeRuntime() once, first thing in main(), while it is the only thread: the vmap CLI, the benchmarks
// and the test binaries do.

#include "vmap/core/option_fields.h"

namespace vmap {

struct RuntimeOptions {
  // OpenCV's own threads per call (cv::setNumThreads); 0 keeps OpenCV's default. vmap runs frames in parallel
  // itself, and OpenCV's threads inside ORB then only add contention (docs/measurements/code-choices.md,
  // "Process-wide settings").
  int opencv_threads = 1;
  // Keep freed memory in the heap instead of returning large blocks to the system (mallopt M_MMAP_MAX = 0,
  // M_TRIM_THRESHOLD = 1 GiB). The deep matchers re-allocate their large activations for every frame; from
  // fresh mmap()s those page-fault every time; kept, LoFTR and ALIKED run clearly faster
  // (docs/measurements/code-choices.md, "Process-wide settings"). The same as starting with
  // GLIBC_TUNABLES=glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=..., without needing the variable.
  bool keep_freed_memory = true;
  // Silence FFmpeg's own log: vmap reports decoding problems itself, once per frame, with the file name;
  // FFmpeg's messages would repeat them without context.
  bool quiet_ffmpeg = true;
  // SIGINT, SIGTERM and SIGHUP remove unfinished outputs and end the process with 128 + the signal
  // (core/interrupt.h). Off in the test binaries, whose death tests install it in their child processes.
  bool handle_interrupts = true;

  // No flags: each host makes its settings (the Python module's initialize_runtime takes them as keywords).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Applies `options` to the process. Call once, before any other thread starts (signal handling blocks the
// signals in the calling thread, and threads started later inherit that); a second call changes the
// settings again but never installs signal handling twice.
void InitializeRuntime(const RuntimeOptions& options = {});

}  // namespace vmap
