#include "vmap/localization/localize_sequence.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <exception>
#include <map>
#include <mutex>
#include <thread>

#include "vmap/core/error.h"
#include "vmap/core/progress.h"

namespace vmap {

int LocalizeSequenceOptions::ExtractionThreads() const {
  if (extraction_threads > 0) return extraction_threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void LocalizeSequenceOptions::Check() const {
  if (extraction_threads < 0 || extraction_threads > 256) {
    throw OptionError("extraction_threads", "must be 0 to 256 (0 = one per core)");
  }
  if (prefetch_frames < 1 || prefetch_frames > 1024) {
    throw OptionError("prefetch_frames", "must be 1 to 1024 (default 4)");
  }
}

namespace {

struct ExtractedFrame {
  Frame frame;
  std::shared_ptr<const ImageFeatures> features;
  std::vector<KeyComparison> ahead;  // comparisons made on the worker
  double extract_seconds = 0.0;
};

using CompareAheadFn = std::function<std::vector<KeyComparison>(const ImageFeatures& features)>;

// Workers take the next frame from the source (one at a time: decoding is sequential) and extract its
// features outside the lock; the consumer receives the frames in order. At most `depth` frames are in
// flight, so memory does not grow with the sequence.
class ExtractionPipeline {
 public:
  ExtractionPipeline(FrameSource& source, const Matcher& matcher, int workers, int depth, CompareAheadFn ahead)
      : source_(source), matcher_(matcher), ahead_(std::move(ahead)), depth_(std::max(depth, workers)) {
    for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { Work(); });
  }

  ~ExtractionPipeline() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  // The next frame in order, or nullopt at the end. Rethrows a worker's error.
  std::optional<ExtractedFrame> Next() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return error_ || ready_.count(next_out_) || (end_ && in_flight_ == 0); });
    if (error_) std::rethrow_exception(error_);
    auto it = ready_.find(next_out_);
    if (it == ready_.end()) return std::nullopt;
    ExtractedFrame item = std::move(it->second);
    ready_.erase(it);
    ++next_out_;
    changed_.notify_all();
    return item;
  }

 private:
  void Work() {
    try {
      while (true) {
        {
          std::unique_lock<std::mutex> lock(mutex_);
          changed_.wait(lock, [this] { return stop_ || end_ || claimed_ - next_out_ < depth_; });
          if (stop_ || end_) return;
          ++claimed_;
          ++in_flight_;
        }
        std::optional<Frame> frame;
        long slot = 0;
        {
          // Sources are read by one thread at a time, in order; slots follow the reading order.
          std::lock_guard<std::mutex> source_lock(source_mutex_);
          if (!source_done_) frame = source_.Next();
          source_done_ = !frame;
          slot = next_in_++;
        }
        if (!frame) {
          std::lock_guard<std::mutex> lock(mutex_);
          end_ = true;
          --in_flight_;
          changed_.notify_all();
          return;
        }
        ExtractedFrame item;
        const auto start = std::chrono::steady_clock::now();
        item.features = matcher_.Extract(frame->gray);
        item.extract_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (ahead_) item.ahead = ahead_(*item.features);
        item.frame = std::move(*frame);
        {
          std::lock_guard<std::mutex> lock(mutex_);
          ready_.emplace(slot, std::move(item));
          --in_flight_;
        }
        changed_.notify_all();
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      changed_.notify_all();
    }
  }

  FrameSource& source_;
  const Matcher& matcher_;
  const CompareAheadFn ahead_;
  const long depth_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;         // everything below but next_in_
  std::mutex source_mutex_;  // source_ and next_in_
  std::condition_variable changed_;
  std::map<long, ExtractedFrame> ready_;
  long next_in_ = 0;   // slot of the next frame read
  bool source_done_ = false;
  long claimed_ = 0;   // slots taken by workers (bounds the frames in flight)
  long next_out_ = 0;
  int in_flight_ = 0;
  bool end_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
};

}  // namespace

LocalizationSummary LocalizeSequence(FrameSource& source, const Matcher& matcher, Localizer& localizer,
                                     const LocalizeSequenceOptions& options, const LocalizationCallback& on_frame) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  LocalizationSummary summary;
  ProgressOptions progress_options;
  progress_options.enabled = options.show_progress;
  ProgressLine progress("localize", source.info().expected_frames, "frames", progress_options);
  double extract_seconds = 0.0, localize_seconds = 0.0;
  // The key images the workers compare new frames with: those of the latest estimate.
  std::mutex likely_mutex;
  std::vector<int> likely_keys = localizer.LikelyKeys();
  CompareAheadFn ahead;
  if (options.compare_ahead) {
    ahead = [&](const ImageFeatures& features) {
      std::vector<int> keys;
      {
        std::lock_guard<std::mutex> lock(likely_mutex);
        keys = likely_keys;
      }
      std::vector<KeyComparison> comparisons;
      for (int key : keys) comparisons.push_back(localizer.Compare(features, key));
      return comparisons;
    };
  }
  {
    ExtractionPipeline pipeline(source, matcher, options.ExtractionThreads(), options.prefetch_frames, ahead);
    while (std::optional<ExtractedFrame> item = pipeline.Next()) {
      const LocalizationResult result = localizer.Localize(item->frame, *item->features, std::move(item->ahead));
      {
        std::lock_guard<std::mutex> lock(likely_mutex);
        likely_keys = localizer.LikelyKeys();
      }
      ++summary.frames;
      switch (result.status) {
        case LocalizationStatus::kTracking: ++summary.tracking; break;
        case LocalizationStatus::kRelocalized: ++summary.relocalized; break;
        case LocalizationStatus::kLost: ++summary.lost; break;
      }
      summary.comparisons += result.comparisons;
      extract_seconds += item->extract_seconds;
      localize_seconds += result.seconds;
      summary.max_localize_seconds = std::max(summary.max_localize_seconds, result.seconds);
      if (on_frame) on_frame(item->frame, result);
      progress.Update(summary.frames);
    }
  }
  progress.Finish();
  summary.skipped_frames = source.skipped_frames();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.frames_per_second = summary.seconds > 0 ? summary.frames / summary.seconds : 0.0;
  if (summary.frames > 0) {
    summary.mean_extract_seconds = extract_seconds / summary.frames;
    summary.mean_localize_seconds = localize_seconds / summary.frames;
  }
  return summary;
}

}  // namespace vmap
