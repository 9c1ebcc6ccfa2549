#pragma once
// Localizes a stream of frames against a map: frames are decoded on a thread of their own and their features extracted
// on worker threads (core/ordered_pipeline.h), a few frames ahead, while the calling thread runs the Localizer on them
// in order. The workers also compare each frame with the key images of the latest estimate (Localizer::LikelyKeys),
// since most frames are compared with the same two key images as the frame before: the calling thread then only
// decides, and compares what the workers did not guess. The results are the same as without, bit for bit (comparisons
// are deterministic, and the Localizer records one only when the frame asks for it). Memory stays flat: only the frames
// in flight are held, and each result goes to the caller as soon as it is known.

#include <functional>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher.h"
#include "vmap/localization/localizer.h"
#include "vmap/sources/frame_source.h"
#include "vmap/sources/odometry.h"

namespace vmap {

struct LocalizeSequenceOptions {
  // Threads decoding frames and extracting their features; 0 = one per core. Extraction of the next frames
  // overlaps with the matching of the current one, so a deep matcher's extraction (XFeat, ALIKED) runs on
  // both cores while ORB's matching and verification keep the calling thread busy.
  int extraction_threads = 0;
  int prefetch_frames = 4;    // frames extracted ahead of the localizer
  bool compare_ahead = true;  // workers compare frames with the likely key images (see above)
  bool show_progress = true;  // a progress line on a terminal

  int ExtractionThreads() const;
  // How a run is carried out: none is recorded; extraction_threads has its flag (--threads), compare_ahead
  // --no-compare-ahead.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct LocalizationSummary {
  long frames = 0;
  long tracking = 0;
  long relocalized = 0;
  long lost = 0;
  long uncertain = 0;
  int skipped_frames = 0;  // frames the source could not decode
  double seconds = 0.0;    // wall time of the run (key images not included)
  double frames_per_second = 0.0;
  double mean_localize_seconds = 0.0;  // Localizer::Localize per frame (matching, verification, ranking)
  double max_localize_seconds = 0.0;
  double mean_extract_seconds = 0.0;  // feature extraction per frame, on the workers
  long comparisons = 0;               // pairs matched and verified
};

using LocalizationCallback = std::function<void(const Frame& frame, const LocalizationResult& result)>;

// Runs `localizer` over every frame of `source` (features from `matcher`, which must be the map's) and
// calls `on_frame` for each frame in order, on the calling thread. `odometry` (may be null): the run's odometry,
// each frame's pose at its timestamp (Frame::odometry) paces the localizer's belief.
LocalizationSummary LocalizeSequence(FrameSource& source, const Matcher& matcher, Localizer& localizer,
                                     const LocalizeSequenceOptions& options, const LocalizationCallback& on_frame,
                                     const OdometryTrack* odometry = nullptr);

}  // namespace vmap
