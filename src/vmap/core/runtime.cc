#include "vmap/core/runtime.h"

#include <malloc.h>

#include <mutex>
#include <string>

#include <opencv2/core.hpp>

extern "C" {
#include <libavutil/log.h>
}

#include "vmap/core/error.h"
#include "vmap/core/interrupt.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void RuntimeOptions::VisitFields(OptionFieldVisitor& visitor) {
  // At most 256, as every thread count of vmap's: far more threads than cores only costs (a pool of 100,000 crashed
  // at exit).
  visitor.Visit(OptionField{"opencv_threads"}.NotRecorded().Within(0, 256).Meaning("0: OpenCV's default"),
                opencv_threads);
  visitor.Visit(OptionField{"keep_freed_memory"}.NotRecorded(), keep_freed_memory);
  visitor.Visit(OptionField{"quiet_ffmpeg"}.NotRecorded(), quiet_ffmpeg);
  visitor.Visit(OptionField{"handle_interrupts"}.NotRecorded(), handle_interrupts);
}

void RuntimeOptions::Check() const { CheckFieldRanges(*this); }

void InitializeRuntime(const RuntimeOptions& options) {
  options.Check();
  if (options.handle_interrupts) {
    // One watcher thread per process (interrupt.h); a second one would only wait beside it.
    static std::once_flag installed;
    std::call_once(installed, InstallInterruptHandling);
  }
  if (options.opencv_threads > 0) cv::setNumThreads(options.opencv_threads);
  if (options.keep_freed_memory) {
    mallopt(M_MMAP_MAX, 0);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
  }
  if (options.quiet_ffmpeg) av_log_set_level(AV_LOG_QUIET);
}

}  // namespace vmap
