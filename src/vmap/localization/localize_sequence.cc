#include "vmap/localization/localize_sequence.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"
#include "vmap/core/ordered_pipeline.h"
#include "vmap/core/progress.h"
#include "vmap/core/stopwatch.h"
#include "vmap/sources/read_ahead_source.h"

namespace vmap {

int LocalizeSequenceOptions::ExtractionThreads() const {
  if (extraction_threads > 0) return extraction_threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void LocalizeSequenceOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section(kRunSection);
  visitor.Visit(OptionField{"extraction_threads", "--threads", "Feature-extraction threads (0 = one per core)"}
                    .NotRecorded()
                    .Within(0, 256)
                    .Meaning("0: one per core"),
                extraction_threads);
  visitor.Visit(OptionField{"prefetch_frames"}.NotRecorded().Within(1, 1024), prefetch_frames);
  visitor.Visit(OptionField{"compare_ahead", "!--no-compare-ahead",
                            "Extraction threads do not compare frames with the likely key images ahead (the results "
                            "are the same)"}
                    .NotRecorded(),
                compare_ahead);
  visitor.Visit(OptionField{"show_progress"}.NotRecorded(), show_progress);
}

void LocalizeSequenceOptions::Check() const { CheckFieldRanges(*this); }

namespace {

struct ExtractedFrame {
  Frame frame;
  std::shared_ptr<const ImageFeatures> features;
  std::vector<KeyComparison> ahead;  // comparisons made on the worker
  double extract_seconds = 0.0;
};

using CompareAheadFn = std::function<std::vector<KeyComparison>(const ImageFeatures& features)>;

}  // namespace

LocalizationSummary LocalizeSequence(FrameSource& source, const Matcher& matcher, Localizer& localizer,
                                     const LocalizeSequenceOptions& options, const LocalizationCallback& on_frame,
                                     const OdometryTrack* odometry) {
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
  auto extract = [&](Frame frame) {
    ExtractedFrame item;
    const auto extract_start = std::chrono::steady_clock::now();
    item.features = matcher.ExtractFrame(frame.gray, frame.color);
    item.extract_seconds = SecondsSince(extract_start);
    if (ahead) item.ahead = ahead(*item.features);
    item.frame = std::move(frame);
    return item;
  };
  auto localize = [&](ExtractedFrame& item) {
    if (odometry && item.frame.timestamp >= 0.0) item.frame.odometry = odometry->At(item.frame.timestamp);
    const LocalizationResult result = localizer.Localize(item.frame, *item.features, std::move(item.ahead));
    {
      std::lock_guard<std::mutex> lock(likely_mutex);
      likely_keys = localizer.LikelyKeys();
    }
    ++summary.frames;
    switch (result.status) {
      case LocalizationStatus::kTracking:
        ++summary.tracking;
        break;
      case LocalizationStatus::kRelocalized:
        ++summary.relocalized;
        break;
      case LocalizationStatus::kLost:
        ++summary.lost;
        break;
      case LocalizationStatus::kUncertain:
        ++summary.uncertain;
        break;
    }
    summary.comparisons += result.comparisons;
    extract_seconds += item.extract_seconds;
    localize_seconds += result.seconds;
    summary.max_localize_seconds = std::max(summary.max_localize_seconds, result.seconds);
    if (on_frame) on_frame(item.frame, result);
    progress.Update(summary.frames);
  };
  {
    // Decoding on a thread of its own, feature extraction (and the comparisons ahead) on the workers; the
    // frames come out in order.
    ReadAheadSource frames(source, options.prefetch_frames);
    const int workers = options.ExtractionThreads();
    OrderedPipeline<Frame, ExtractedFrame> pipeline(std::max(options.prefetch_frames, workers), workers, extract);
    while (std::optional<Frame> frame = frames.Next()) {
      while (!pipeline.TryPush(*frame)) {
        std::optional<ExtractedFrame> item = pipeline.Next();  // a frame is in flight: one comes out
        localize(*item);
      }
      while (std::optional<ExtractedFrame> item = pipeline.TryNext()) localize(*item);
    }
    pipeline.Close();
    while (std::optional<ExtractedFrame> item = pipeline.Next()) localize(*item);
  }
  progress.Finish();
  summary.skipped_frames = source.skipped_frames();
  summary.seconds = SecondsSince(start);
  summary.frames_per_second = summary.seconds > 0 ? summary.frames / summary.seconds : 0.0;
  if (summary.frames > 0) {
    summary.mean_extract_seconds = extract_seconds / summary.frames;
    summary.mean_localize_seconds = localize_seconds / summary.frames;
  }
  return summary;
}

}  // namespace vmap
