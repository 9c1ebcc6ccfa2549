#include "vmap/mapping/map_builder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/bounded_queue.h"
#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/progress.h"
#include "vmap/core/reorder_buffer.h"
#include "vmap/core/serial_worker.h"
#include "vmap/map/map_io.h"
#include "vmap/map/map_writer.h"
#include "vmap/sources/read_ahead_source.h"

namespace vmap {
namespace fs = std::filesystem;

KeySearch ParseKeySearch(const std::string& name) { return ParseEnum(kKeySearchNames, name, "key-image search"); }

std::string KeySearchName(KeySearch search) { return EnumToName(kKeySearchNames, search); }

KeySearch ResolveKeySearch(const MapBuilderOptions& options) {
  return options.key_search == KeySearch::kAuto ? KeySearch::kSequential : options.key_search;
}

void MapBuilderOptions::Check() const {
  CheckField("key_images", key_images);
  CheckField("verifier", verifier);
  CheckField("link_analysis", link_analysis);
  if (prefetch_frames < 1 || prefetch_frames > 1024) throw OptionError("prefetch_frames", "must be 1 to 1024");
  if (extraction_threads < 0 || extraction_threads > kMaxExtractionThreads) {
    throw OptionError("extraction_threads",
                      "must be 0 to " + std::to_string(kMaxExtractionThreads) + " (0 = one per core)");
  }
  if (exhaustive && key_search == KeySearch::kBisect) {
    throw OptionError("exhaustive", "is the paper's frame-by-frame scan and key_search bisect skips frames; drop one",
                      {"key_search"});
  }
  if (search_window < 2 || search_window > 4096) {
    throw OptionError("search_window", "must be 2 to 4096 frames (default 32)");
  }
}

int MapBuilderOptions::ExtractionThreads() const {
  if (extraction_threads > 0) return extraction_threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

namespace {

// Compares a key image with a frame for the selectors whose thresholds are `taus`; `abandon` may stop it.
using CompareFn = std::function<PairComparison(const FrameRecord& key, const FrameRecord& frame,
                                               const std::vector<double>& taus, const std::function<bool()>& abandon)>;

// The thresholds the comparison of frame `frame_index` with key image `key_index` settles, fixed by the maps
// alone (never by the threads' timing: where an estimation that stops early stops, and so its S, depends on
// every threshold it settles). The previous frame may become any selector's key image during this frame, so its
// comparison settles every threshold; an older key image is compared for the selectors holding it when the
// frame comes (`holders`, ascending), and for `tau` (a selector that moves to it during the frame, after frames
// that repeated the key image's view). Without holders: every threshold.
// Adds `tau` to the ascending `taus` unless it is there.
void AddThreshold(double tau, std::vector<double>* taus) {
  if (!std::binary_search(taus->begin(), taus->end(), tau)) {
    taus->insert(std::upper_bound(taus->begin(), taus->end(), tau), tau);
  }
}

std::vector<double> ThresholdsToSettle(int key_index, int frame_index, const std::vector<double>* holders,
                                       const std::vector<double>& all_taus, double tau) {
  std::vector<double> taus = key_index == frame_index - 1 || !holders ? all_taus : *holders;
  AddThreshold(tau, &taus);
  return taus;
}

// A key image the workers compare frames with, and the thresholds (ascending) of the selectors that hold it.
struct CurrentKey {
  FrameRecord record;
  std::vector<double> taus;
};

// A frame with its features and the comparisons the workers already made for it (by key frame index).
struct PipelineItem {
  FrameRecord record;
  std::map<int, PairComparison> comparisons;
};

// Takes frames from the consumer (TryPush) and, on `workers` threads, extracts their features and compares
// them with the current key images, a few frames ahead of the consumer, which receives them in order (Next).
// The frames in flight are bounded by `depth`; the frames come decoded (BuildMap reads them ahead on a thread
// of their own, ReadAheadSource).
//
// Why compare ahead: a frame is compared with the same key image as the frames before it until S drops,
// so those comparisons do not depend on each other and can run in parallel.
//
// Key changes are followed by the workers too. When a worker sees frame j fall below tau against a key
// image, every selector holding that key with tau or a higher threshold leaves it at frame j at the latest,
// for frame j-1 (or for j itself when j-1 is that key: a link below tau); the others keep it. Frame j and the
// later ones are compared with that successor at once for those thresholds, as the consumer will ask, instead
// of with the old key at low S, where the estimator works longest only for the result to be thrown away, and
// the consumer then redoing the comparisons one by one while the workers wait. A comparison whose every
// threshold left its key at an earlier frame meanwhile is abandoned.
//
// The consumer compares whatever the workers did not guess (also when the selector picks another successor,
// as it does for a frame that repeats the key image's view). ComparePair is deterministic, so the map is the
// same whatever the threads do.
class FeaturePipeline {
 public:
  // `all_taus`: every selector's threshold, ascending.
  FeaturePipeline(const Matcher& matcher, int depth, int workers, CompareFn compare, std::vector<double> all_taus)
      : matcher_(matcher),
        compare_(std::move(compare)),
        all_taus_(std::move(all_taus)),
        depth_(std::max(depth, workers + 1)),
        to_extract_(static_cast<size_t>(depth_)) {
    try {
      for (int i = 0; i < workers; ++i) workers_.emplace_back([this] { Work(); });
    } catch (const std::system_error& error) {
      // The system refused a thread (a process limit): stop those already started, or their destructors abort.
      Stop();
      throw InputError("cannot start " + std::to_string(workers) + " threads (" + error.what() +
                       "); use fewer extraction threads");
    }
  }

  ~FeaturePipeline() { Stop(); }

  // Hands `frame` to the workers, unless `depth` frames are in the pipeline already: then false, and `frame`
  // is left as it was (take an item out with Next() first). Rethrows a worker's error.
  bool TryPush(Frame& frame) {
    results_.RethrowIfFailed();
    if (closed_) throw std::logic_error("FeaturePipeline::TryPush after Close");
    if (pushed_ - next_out_ >= depth_) return false;
    // Never waits: the queue holds at most the frames in flight, fewer than its capacity.
    to_extract_.Push({pushed_++, std::move(frame)});
    return true;
  }

  // No more frames: Next() returns nullopt once every frame pushed has come out.
  void Close() {
    closed_ = true;
    to_extract_.Close();
  }

  // The key images (distinct) that frames extracted from now on are compared with, each with the thresholds
  // of the selectors holding it: a frame below the lowest makes all of them leave the key.
  void SetCurrentKeys(std::vector<CurrentKey> keys) {
    auto shared = std::make_shared<const std::vector<CurrentKey>>(std::move(keys));
    std::lock_guard<std::mutex> lock(mutex_);
    current_keys_ = std::move(shared);
  }

  // The next frame in order, waiting for it; nullopt at the end (after Close). Rethrows a worker's error.
  std::optional<PipelineItem> Next() {
    if (next_out_ == pushed_) {
      if (closed_) return std::nullopt;
      throw std::logic_error("FeaturePipeline::Next with no frame in flight");
    }
    return Took(results_.Take(next_out_));
  }

  // The next frame when it is ready now, otherwise nullopt.
  std::optional<PipelineItem> TryNext() {
    if (next_out_ == pushed_) return std::nullopt;
    std::optional<PipelineItem> item = results_.TryTake(next_out_);
    if (!item) return std::nullopt;
    return Took(std::move(*item));
  }

  long extracted() const { return extracted_; }

 private:
  void Stop() {
    stop_ = true;
    to_extract_.Close();
    for (std::thread& worker : workers_) worker.join();
  }

  PipelineItem Took(PipelineItem item) {
    ++next_out_;
    // A successor is a frame at most a pipeline's depth behind the consumer; keep a margin.
    std::lock_guard<std::mutex> lock(mutex_);
    recent_.erase(recent_.begin(), recent_.lower_bound(static_cast<int>(next_out_) - 2 * depth_));
    return item;
  }

  // A worker: frames from the queue until it closes; an error stops the pipeline and reaches the consumer.
  void Work() {
    while (std::optional<std::pair<long, Frame>> decoded = to_extract_.Pop()) {
      if (stop_) continue;  // stopping: drain without work
      try {
        results_.Put(decoded->first, ExtractAndCompare(std::move(decoded->second)));
      } catch (...) {
        stop_ = true;
        results_.Fail(std::current_exception());
        to_extract_.Close();
      }
    }
  }

  PipelineItem ExtractAndCompare(Frame decoded) {
    PipelineItem item;
    item.record.features = RethrowAsInputError(
        [&] {
          return ErrorContext{"the " + matcher_.name() + " matcher failed on frame " +
                                  std::to_string(decoded.source_index) + " (" + decoded.source_name + ")",
                              "check the frame, or try other matcher options"};
        },
        [&] { return matcher_.Extract(decoded.gray); });
    item.record.frame = std::make_shared<const Frame>(std::move(decoded));
    ++extracted_;
    const int frame_index = item.record.frame->index;
    std::shared_ptr<const std::vector<CurrentKey>> keys;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      recent_.emplace(frame_index, item.record);
      keys = current_keys_;  // taken after extraction: the freshest the consumer has published
    }
    // Compare as the consumer will: each selector's tau with the key it will hold at this frame, i.e. its
    // published key, or the successor of a key that this frame or an earlier one fell below that tau against
    // (and so on), grouping the taus that meet on one key; until every group is compared, is the frame itself,
    // or waits for a successor not extracted yet (the consumer then compares).
    while (keys) {
      std::map<int, CurrentKey> groups;  // by the key the taus resolve to
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const CurrentKey& current : *keys) {
          for (double tau : current.taus) {
            const int index = ResolveKey(current.record.frame->index, tau, frame_index);
            if (index == frame_index || item.comparisons.count(index)) continue;
            const FrameRecord* record = &current.record;
            if (index != current.record.frame->index) {
              const auto found = recent_.find(index);
              if (found == recent_.end()) continue;
              record = &found->second;
            }
            CurrentKey& group = groups.emplace(index, CurrentKey{*record, {}}).first->second;
            group.taus.push_back(tau);
          }
        }
      }
      if (groups.empty()) break;
      CurrentKey& group = groups.begin()->second;
      std::sort(group.taus.begin(), group.taus.end());
      const int key_index = group.record.frame->index;
      // Abandoned when other workers find, meanwhile, an earlier frame below every one of these taus: this
      // frame then goes on to the successors.
      std::vector<double> asked;
      {
        // The holders when this frame comes, as far as the workers know: the selectors whose key resolves to
        // this one at the previous frame.
        std::vector<double> holders;
        std::lock_guard<std::mutex> lock(mutex_);
        for (const CurrentKey& current : *keys) {
          for (double tau : current.taus) {
            if (ResolveKey(current.record.frame->index, tau, frame_index - 1) == key_index) holders.push_back(tau);
          }
        }
        std::sort(holders.begin(), holders.end());
        asked = ThresholdsToSettle(key_index, frame_index, holders.empty() ? nullptr : &holders, all_taus_,
                                   group.taus.front());
        for (double tau : group.taus) AddThreshold(tau, &asked);
      }
      PairComparison comparison =
          compare_(group.record, item.record, asked, [this, key_index, frame_index, &group] {
            std::lock_guard<std::mutex> lock(mutex_);
            for (double tau : group.taus) {
              if (ResolveKey(key_index, tau, frame_index - 1) == key_index) return false;
            }
            return true;
          });
      if (comparison.abandoned) continue;
      for (double tau : group.taus) {
        if (!(comparison.matched && comparison.similarity >= tau)) {
          Retire(key_index, frame_index, tau);  // this tau and every higher one leave the key here
          break;
        }
      }
      item.comparisons.emplace(key_index, std::move(comparison));
    }
    return item;
  }

  // The key image a selector with threshold `tau` that held `key_index` compares `frame_index` with, as far as
  // the workers know: that key, or the successor of a key that this frame or an earlier one fell below tau
  // against, and so on. Call with mutex_ held.
  int ResolveKey(int key_index, double tau, int frame_index) const {
    for (;;) {
      const Retirement* first = nullptr;
      const auto events = retired_.find(key_index);
      if (events == retired_.end()) return key_index;
      for (const Retirement& event : events->second) {
        if (event.at_frame <= frame_index && tau >= event.from_tau && (!first || event.at_frame < first->at_frame)) {
          first = &event;
        }
      }
      if (!first) return key_index;
      key_index = first->successor;  // always a later frame: the chain ends
    }
  }

  // Frame `frame_index` fell below `tau` against the key image `key_index`: the selectors holding it with tau
  // or a higher threshold leave it here at the latest, for the successor Algorithm 1 gives.
  void Retire(int key_index, int frame_index, double tau) {
    const int successor = KeyImageSelector::SuccessorOf(key_index, frame_index);
    std::lock_guard<std::mutex> lock(mutex_);
    retired_[key_index].push_back(Retirement{frame_index, tau, successor});
  }

  const Matcher& matcher_;
  const CompareFn compare_;
  const std::vector<double> all_taus_;
  const int depth_;
  // The consumer's side: frames handed over and taken out (in flight: the difference).
  long pushed_ = 0;
  long next_out_ = 0;
  bool closed_ = false;
  BoundedQueue<std::pair<long, Frame>> to_extract_;  // decoded frames waiting for a worker, numbered
  ReorderBuffer<PipelineItem> results_;              // extracted and compared, by number
  std::atomic<bool> stop_{false};
  std::atomic<long> extracted_{0};
  // What the workers share to follow key changes.
  std::mutex mutex_;
  std::shared_ptr<const std::vector<CurrentKey>> current_keys_;
  struct Retirement {
    int at_frame;    // a frame seen to fall below from_tau against the key
    double from_tau;  // the lowest threshold it fell below: selectors with this tau or a higher one leave
    int successor;   // the frame that replaces the key for them
  };
  std::map<int, std::vector<Retirement>> retired_;  // by key frame index
  std::map<int, FrameRecord> recent_;    // extracted frames a successor may be taken from, by frame index
  std::vector<std::thread> workers_;     // last: started once everything they use exists
};

// Verifies links in full, on a thread of its own while the build goes on, when the decisions stopped early:
// the tables are then computed from exact link values. The estimation goes on from where the deciding
// comparison stopped, on the link's own tentative matches (no matching, no features kept). A link shared by
// several taus (same two frames) is verified once.
class LinkVerifier {
 public:
  explicit LinkVerifier(const VerifierOptions& verifier) : verifier_(verifier) {}

  // Queues `link`, between key images `from` and `to`, unless that pair of frames is queued already.
  // `checkpoint`, where the comparison that made the link stopped, saves the samples it drew already.
  void Add(const KeyImage& from, const KeyImage& to, const Link& link, SimilarityMode similarity,
           std::shared_ptr<const MagsacCheckpoint> checkpoint) {
    const auto pair = std::make_pair(from.frame_index, to.frame_index);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!results_.emplace(pair, PairComparison{}).second) return;
    }
    TentativeMatches matches;
    for (const Correspondence& c : link.correspondences) {
      matches.points0.push_back(c.p0);
      matches.points1.push_back(c.p1);
    }
    const int denominator = similarity == SimilarityMode::kInlierRatio
                                ? link.num_tentative
                                : std::max(from.num_features, to.num_features);
    worker_.Post([this, pair, matches = std::move(matches), denominator, checkpoint = std::move(checkpoint)] {
      PairComparison verified = VerifyMatches(matches, denominator, verifier_, {}, nullptr, checkpoint);
      std::lock_guard<std::mutex> lock(mutex_);
      results_[pair] = std::move(verified);
    });
  }

  // Waits for every link queued so far (a snapshot applies them); rethrows a failure.
  void Wait() { worker_.Wait(); }

  // Waits for every verification; rethrows a failure. Returns how many links were verified.
  long Finish() {
    worker_.Wait();
    return static_cast<long>(results_.size());
  }

  // Replaces the links of `map`, built with threshold `tau`, by their verifications (after Finish). A verification
  // that contradicts the decision (a link at S >= tau found below tau, or the reverse for a link below tau: the
  // two estimates differ by the noise of a seed change) leaves the deciding comparison in place, so that every
  // link keeps the meaning Algorithm 1 gives it.
  // Returns how many links kept their deciding comparison.
  int Apply(VisualMap* map, double tau) const {
    int kept = 0;
    for (Link& link : map->links) {
      const auto pair = std::make_pair(map->key_images[link.from_key].frame_index,
                                       map->key_images[link.to_key].frame_index);
      const PairComparison& verified = results_.at(pair);
      if ((verified.matched && verified.similarity >= tau) == !link.below_tau) {
        link = MakeLink(verified, link.from_key, link.to_key, link.below_tau);
      } else {
        ++kept;
      }
    }
    return kept;
  }

 private:
  const VerifierOptions verifier_;
  std::mutex mutex_;
  std::map<std::pair<int, int>, PairComparison> results_;  // by (from, to) frame index
  SerialWorker worker_;  // last: destroyed first, so its jobs never outlive results_
};

// `link_verifier` (when the decisions stopped early): the links verified in full replace the deciding ones.
// `analyze_links`: also each link's pose, parallax and homography test (only maps that are kept need them),
// reusing those of `analysis_cache` where the links did not change.
VisualMap CollectMap(const KeyImageSelector& selector, const FrameSource& source, const MapBuilderOptions& options,
                     const std::string& options_json, double seconds, bool analyze_links,
                     const LinkVerifier* link_verifier = nullptr, double tau = 0.0,
                     LinkAnalysisCache* analysis_cache = nullptr) {
  VisualMap map;
  map.input = source.info();
  map.options_json = options_json;
  map.num_frames = selector.num_frames();
  map.skipped_frames = source.skipped_frames();
  map.key_images = selector.key_images();
  map.links = selector.links();
  map.evaluations = selector.evaluations();
  map.seconds = seconds;
  if (link_verifier) {
    const int kept = link_verifier->Apply(&map, tau);
    if (kept > 0) {
      spdlog::debug("tau {:.2f}: {} of {} links kept the deciding estimate (the full one crossed tau)", tau, kept,
                    map.links.size());
    }
  }
  map.quality = ComputeStatistics(map, options.quality_mean).quality;
  if (!analyze_links) return map;
  const auto analysis_start = std::chrono::steady_clock::now();
  const long reused_before = analysis_cache ? analysis_cache->hits() : 0;
  AnalyzeLinks(map, options.link_analysis, options.ExtractionThreads(), analysis_cache);
  const double analysis_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - analysis_start).count();
  spdlog::debug("pose, parallax and homography test of {} links in {:.3f} s ({} analysed before)", map.links.size(),
                analysis_seconds, analysis_cache ? analysis_cache->hits() - reused_before : 0);
  map.seconds += analysis_seconds;  // part of building the map
  return map;
}

std::vector<double> Sorted(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values;
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::vector<double> ParseThresholds(const std::string& text) {
  std::vector<double> taus;
  double start, stop, step;
  char extra;
  if (std::sscanf(text.c_str(), "%lf:%lf:%lf%c", &start, &stop, &step, &extra) == 3) {
    if (!std::isfinite(start) || !std::isfinite(stop) || !(step > 0) || !std::isfinite(step) || stop < start) {
      throw OptionError("thresholds", "'" + text + "' must be start:stop:step with step > 0 and stop >= start");
    }
    // Count steps with a tolerance so that 0.1:0.9:0.1 includes 0.9; counted in double before anything is
    // allocated, so that a tiny step is refused rather than filling the memory.
    const double count = std::floor((stop - start) / step + 1e-9) + 1;
    if (count > kMaxThresholds) {
      throw OptionError("thresholds", fmt::format("'{}' gives {:.0f} thresholds, more than {}; use a larger step",
                                                  text, count, kMaxThresholds));
    }
    for (int i = 0; i < static_cast<int>(count); ++i) taus.push_back(std::round((start + i * step) * 1e9) / 1e9);
  } else {
    std::stringstream list(text);
    std::string item;
    while (std::getline(list, item, ',')) {
      try {
        size_t used = 0;
        taus.push_back(std::stod(item, &used));
        if (used != item.size()) throw std::invalid_argument(item);
      } catch (const std::exception&) {
        throw OptionError("thresholds", "'" + text + "' is not start:stop:step (0.1:0.9:0.1) or a list (0.2,0.5)");
      }
      if (taus.size() > kMaxThresholds) {
        throw OptionError("thresholds",
                          "'" + text + "' lists more than " + std::to_string(kMaxThresholds) + " thresholds");
      }
    }
  }
  if (taus.empty()) throw OptionError("thresholds", "'" + text + "' gives no threshold");
  for (size_t i = 0; i < taus.size(); ++i) {
    KeyImageOptions check;
    check.tau = taus[i];
    check.Check();
    for (size_t j = 0; j < i; ++j) {
      if (taus[j] == taus[i]) throw OptionError("thresholds", fmt::format("'{}' gives tau = {} twice", text, taus[i]));
    }
  }
  return taus;
}

namespace {

// The verifier of the decisions: vmap's MAGSAC++, stopping once S >= tau is settled, unless the paper's
// exact behaviour is asked for (or another verifier, which OpenCV runs to its confidence criterion).
VerifierOptions DecisionVerifier(const MapBuilderOptions& options) {
  VerifierOptions verifier = options.verifier;
  verifier.own_magsac = !options.exhaustive && verifier.method == VerifierMethod::kMagsac;
  return verifier;
}

}  // namespace

// The streaming state of a build: the pipeline, one selector per tau, the link verifier and the sinks.
class MapBuilder::Impl {
 public:
  Impl(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options, std::vector<double> taus,
       std::vector<MapWriter*> writers, std::string options_json)
      : source_(source),
        options_(options),
        taus_(std::move(taus)),
        sorted_taus_(Sorted(taus_)),
        writers_(std::move(writers)),
        options_json_(std::move(options_json)),
        start_(std::chrono::steady_clock::now()),
        verifier_(DecisionVerifier(options)),
        stops_early_(verifier_.own_magsac),
        progress_(taus_.size() == 1 ? "build" : "sweep", std::max(0L, source.info().expected_frames), "frames",
                  ProgressOptions{options.show_progress}) {
    options_.Check();
    if (taus_.empty()) throw std::logic_error("MapBuilder without a threshold");
    writers_.resize(taus_.size(), nullptr);
    compare_pair_ = [this, &matcher](const FrameRecord& key, const FrameRecord& frame,
                                     const std::vector<double>& decide_taus, const std::function<bool()>& abandon) {
      ++pairs_matched_;
      PairComparison comparison = RethrowAsInputError(
          [&] {
            return ErrorContext{"matching frame " + std::to_string(frame.frame->source_index) + " (" +
                                    frame.frame->source_name + ") with key image " +
                                    std::to_string(key.frame->source_index) + " (" + key.frame->source_name +
                                    ") failed",
                                "check the frames, or try other matcher or verifier options"};
          },
          [&] {
            return ComparePair(matcher, *key.features, *frame.features, verifier_, options_.key_images.similarity,
                               stops_early_ ? decide_taus : std::vector<double>{}, abandon);
          });
      if (comparison.abandoned) ++pairs_abandoned_;
      return comparison;
    };
    for (size_t i = 0; i < taus_.size(); ++i) {
      KeyImageOptions key_options = options_.key_images;
      key_options.tau = taus_[i];
      KeyImageSelector::KeyImageFn on_key_image;
      KeyImageSelector::EvaluationFn on_evaluation;
      if (MapWriter* writer = writers_[i]) {
        on_key_image = [writer](const FrameRecord& record, KeyImage& key) {
          key.image_file = writer->AddKeyImage(record.frame);
        };
        on_evaluation = [writer](const Evaluation& evaluation) { writer->AddEvaluation(evaluation); };
      }
      // Links keep a full estimation when the decisions stopped early; queued as soon as each link is made.
      KeyImageSelector::LinkFn on_link = [this, i](const Link& link, const PairComparison& comparison) {
        if (!link_verifier_) return;
        const std::vector<KeyImage>& keys = selectors_[i]->key_images();
        link_verifier_->Add(keys[link.from_key], keys[link.to_key], link, options_.key_images.similarity,
                            comparison.checkpoint);
      };
      selectors_.push_back(std::make_unique<KeyImageSelector>(key_options, CompareFor(taus_[i]),
                                                              std::move(on_key_image), std::move(on_evaluation),
                                                              std::move(on_link)));
    }
    if (stops_early_) link_verifier_ = std::make_unique<LinkVerifier>(VerifierOptions(verifier_));
    link_analyses_.resize(selectors_.size());
    pipeline_ = std::make_unique<FeaturePipeline>(matcher, options_.prefetch_frames, options_.ExtractionThreads(),
                                                  compare_pair_, sorted_taus_);
  }

  void Add(Frame frame) {
    if (finished_) throw std::logic_error("MapBuilder::Add after Finish");
    if (first_source_index_ < 0) first_source_index_ = frame.source_index;
    last_source_index_ = frame.source_index;
    while (!pipeline_->TryPush(frame)) {
      std::optional<PipelineItem> item = pipeline_->Next();  // a frame is in flight: one comes out
      if (!item) throw std::logic_error("FeaturePipeline ended while frames were in flight");
      Process(*item);
    }
    while (std::optional<PipelineItem> item = pipeline_->TryNext()) Process(*item);
  }

  void Snapshot() {
    if (finished_) throw std::logic_error("MapBuilder::Snapshot after Finish");
    if (link_verifier_) link_verifier_->Wait();
    for (size_t i = 0; i < selectors_.size(); ++i) {
      // Nothing to write before Algorithm 1 has taken its first frame.
      if (!writers_[i] || selectors_[i]->key_images().empty()) continue;
      VisualMap map = CollectMap(*selectors_[i], source_, options_, options_json_, SecondsSince(start_),
                                 /*analyze_links=*/true, link_verifier_.get(), taus_[i], &link_analyses_[i]);
      map.coverage = CurrentCoverage(CoverageEnd::kSnapshot);
      writers_[i]->Snapshot(map);
    }
  }

  std::vector<VisualMap> Finish(CoverageEnd end, bool analyze_links, bool with_evaluations) {
    if (finished_) throw std::logic_error("MapBuilder::Finish called twice");
    finished_ = true;
    pipeline_->Close();
    while (std::optional<PipelineItem> item = pipeline_->Next()) Process(*item);
    progress_.Finish();
    features_extracted_ = pipeline_->extracted();
    pipeline_.reset();
    for (auto& selector : selectors_) selector->Finish();  // the final key images
    long evaluations = 0;
    for (const auto& selector : selectors_) evaluations += static_cast<long>(selector->evaluations().size());
    for (MapWriter* writer : writers_) evaluations += writer ? writer->num_evaluations() : 0;
    if (link_verifier_) links_verified_ = link_verifier_->Finish();
    spdlog::debug("{} pairs matched and verified for {} evaluations, {} abandoned; {} links verified in full",
                  pairs_matched_.load(), evaluations, pairs_abandoned_.load(), links_verified_);
    const double seconds = SecondsSince(start_);
    std::vector<VisualMap> maps;
    for (size_t i = 0; i < selectors_.size(); ++i) {
      VisualMap map = CollectMap(*selectors_[i], source_, options_, options_json_, seconds, analyze_links,
                                 link_verifier_.get(), taus_[i], &link_analyses_[i]);
      // A map of a whole file says nothing more (its map.json stays as it was); a live input's says what it
      // covers.
      if (end != CoverageEnd::kInputEnded || source_.info().expected_frames < 0) map.coverage = CurrentCoverage(end);
      if (writers_[i]) writers_[i]->Finish(map, with_evaluations ? &map.evaluations : nullptr);
      maps.push_back(std::move(map));
    }
    return maps;
  }

  long features_extracted() const { return features_extracted_; }
  long pairs_matched() const { return pairs_matched_; }
  long links_verified() const { return links_verified_; }
  double seconds() const { return SecondsSince(start_); }

 private:
  // The comparisons of the current frame, by key frame: made ahead by the pipeline, or here when a key image
  // changed meanwhile. A pair compared under several taus is matched once. A comparison that stopped early is
  // used only when it settled exactly ThresholdsToSettle: the workers guess which selectors will hold a key
  // image, and a comparison made for another set could give another S, and another decision (before this, a
  // sweep could give other tables from one run to the next).
  KeyImageSelector::CompareFn CompareFor(double tau) {
    return [this, tau](const FrameRecord& key, const FrameRecord& frame) -> PairComparison {
      const int key_index = key.frame->index;
      const auto held = holders_.find(key_index);
      const std::vector<double> asked = ThresholdsToSettle(
          key_index, frame.frame->index, held != holders_.end() ? &held->second : nullptr, sorted_taus_, tau);
      auto it = comparisons_of_frame_->find(key_index);
      if (it != comparisons_of_frame_->end() && (it->second.exhaustive || it->second.decided_taus == asked)) {
        return it->second;
      }
      return (*comparisons_of_frame_)[key_index] = compare_pair_(key, frame, asked, nullptr);
    };
  }

  void Process(PipelineItem& item) {
    comparisons_of_frame_ = &item.comparisons;
    for (auto& selector : selectors_) selector->Add(item.record);
    comparisons_of_frame_ = nullptr;
    // Tell the workers which key images the coming frames will be compared with (a handful of shared pointers:
    // cheaper to publish every frame than to track changes).
    std::map<int, CurrentKey> keys;  // by key frame index
    for (size_t i = 0; i < selectors_.size(); ++i) {
      const FrameRecord* key = selectors_[i]->current_key();
      if (!key) continue;
      keys.emplace(key->frame->index, CurrentKey{*key, {}}).first->second.taus.push_back(taus_[i]);
    }
    holders_.clear();
    std::vector<CurrentKey> current;
    for (auto& [index, key] : keys) {
      std::sort(key.taus.begin(), key.taus.end());
      holders_[index] = key.taus;
      current.push_back(std::move(key));
    }
    pipeline_->SetCurrentKeys(std::move(current));
    progress_.Update(++frames_done_);
  }

  Coverage CurrentCoverage(CoverageEnd end) const {
    Coverage coverage;
    coverage.num_frames = selectors_.front()->num_frames();
    coverage.first_source_index = first_source_index_;
    coverage.last_source_index = last_source_index_;
    coverage.end = end;
    return coverage;
  }

  const FrameSource& source_;
  const MapBuilderOptions options_;
  const std::vector<double> taus_;  // selector i's is taus_[i]
  const std::vector<double> sorted_taus_;
  std::vector<MapWriter*> writers_;
  const std::string options_json_;
  const std::chrono::steady_clock::time_point start_;
  const VerifierOptions verifier_;
  const bool stops_early_;
  ProgressLine progress_;
  CompareFn compare_pair_;
  std::atomic<long> pairs_matched_{0}, pairs_abandoned_{0};
  std::map<int, PairComparison>* comparisons_of_frame_ = nullptr;
  std::map<int, std::vector<double>> holders_;  // key frame index -> taus of the selectors holding it
  std::vector<std::unique_ptr<KeyImageSelector>> selectors_;
  std::vector<LinkAnalysisCache> link_analyses_;  // per selector: what snapshots analysed stays analysed
  std::unique_ptr<LinkVerifier> link_verifier_;
  long frames_done_ = 0;
  int first_source_index_ = -1;
  int last_source_index_ = -1;
  long features_extracted_ = 0;
  long links_verified_ = 0;
  bool finished_ = false;
  std::unique_ptr<FeaturePipeline> pipeline_;  // last: its workers stop before what they use goes
};

MapBuilder::MapBuilder(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                       MapWriter* writer, std::string options_json)
    : MapBuilder(source, matcher, options, {options.key_images.tau}, {writer}, std::move(options_json)) {}

MapBuilder::MapBuilder(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                       std::vector<double> taus, std::vector<MapWriter*> writers, std::string options_json) {
  if (ResolveKeySearch(options) == KeySearch::kBisect) {
    throw OptionError("key_search",
                      "bisect reads ahead of the frames it is given, so it cannot build a map one frame at a time "
                      "(live inputs, snapshots); use key_search sequential",
                      {"key_search"});
  }
  impl_ = std::make_unique<Impl>(source, matcher, options, std::move(taus), std::move(writers),
                                 std::move(options_json));
}

MapBuilder::~MapBuilder() = default;

void MapBuilder::Add(Frame frame) { impl_->Add(std::move(frame)); }
void MapBuilder::Snapshot() { impl_->Snapshot(); }
std::vector<VisualMap> MapBuilder::FinishAll(CoverageEnd end, bool analyze_links, bool with_evaluations) {
  return impl_->Finish(end, analyze_links, with_evaluations);
}
VisualMap MapBuilder::Finish(CoverageEnd end) { return std::move(impl_->Finish(end, true, false).front()); }
long MapBuilder::features_extracted() const { return impl_->features_extracted(); }
long MapBuilder::pairs_matched() const { return impl_->pairs_matched(); }
long MapBuilder::links_verified() const { return impl_->links_verified(); }

namespace {

// Runs one selector per tau over one pass of the source; directories[i] receives tau i's map (no directory:
// the map stays in memory only). Maps returned whole, their evaluations read back from the writers.
SweepResult RunSelectors(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                         const std::vector<double>& taus, const std::vector<fs::path>& directories,
                         std::vector<VisualMap>* maps, const std::string& options_json) {
  options.Check();
  std::vector<std::unique_ptr<MapWriter>> writers;
  std::vector<MapWriter*> sinks;
  for (const fs::path& directory : directories) {
    writers.push_back(directory.empty() ? nullptr : std::make_unique<MapWriter>(directory));
    sinks.push_back(writers.back().get());
  }
  // Maps are only written when they are kept (vmap sweep --keep-maps, BuildMap): their links need analysing.
  const bool analyze_links = maps != nullptr;
  // Decoding on a thread of its own overlaps with Algorithm 1 on this one (measured: without it, lab_floor's
  // build took longer, side by side).
  ReadAheadSource frames(source, options.prefetch_frames);
  MapBuilder builder(frames, matcher, options, taus, sinks, options_json);
  while (std::optional<Frame> frame = frames.Next()) {
    builder.Add(std::move(*frame));
    if (options.after_frame) options.after_frame();
  }
  std::vector<VisualMap> built = builder.FinishAll(CoverageEnd::kInputEnded, analyze_links, /*with_evaluations=*/true);

  SweepResult result;
  result.options_json = options_json;
  result.input = frames.info();
  result.features_extracted = builder.features_extracted();
  result.pairs_matched = builder.pairs_matched();
  result.links_verified = builder.links_verified();
  for (size_t i = 0; i < built.size(); ++i) {
    VisualMap& map = built[i];
    result.seconds = std::max(result.seconds, map.seconds);
    const MapStatistics stats = ComputeStatistics(map, options.quality_mean);
    result.num_frames = map.num_frames;
    SweepRow row;
    row.tau = taus[i];
    row.num_key_images = stats.num_key_images;
    row.key_image_percent = stats.num_frames > 0 ? 100.0 * stats.num_key_images / stats.num_frames : 0.0;
    row.min_verified = stats.min_verified;
    row.max_verified = stats.max_verified;
    row.mean_verified = stats.mean_verified;
    row.mean_similarity = stats.mean_similarity;
    row.quality = stats.quality;
    row.below_tau_links = stats.below_tau_links;
    row.map_directory = directories[i].string();
    result.rows.push_back(row);
    if (result.best_row < 0 || row.quality > result.rows[result.best_row].quality) {
      result.best_row = static_cast<int>(i);
    }
    if (maps) maps->push_back(std::move(map));
  }
  return result;
}

// Algorithm 1 with a search for the first frame below tau instead of a frame-by-frame scan. From the key image
// and the last frame known to pass against it, frames ever further ahead are compared (offsets doubling, at
// most search_window ahead), then the first failing frame is found by bisection. The last passing frame and the
// first failing one are then given to a KeyImageSelector, which, from the cached comparisons, makes the key
// images, links and links below tau Algorithm 1 makes on the whole sequence wherever S decreases with the
// distance to the key image. Each round compares one frame per thread at once; a frame's features are extracted
// only when it is compared, and only the frames the search may still compare are held.
VisualMap SearchKeyImages(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                          const fs::path& directory, const std::string& options_json) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const VerifierOptions verifier = DecisionVerifier(options);
  const std::vector<double> taus = verifier.own_magsac ? std::vector<double>{options.key_images.tau}
                                                       : std::vector<double>{};
  const int workers = options.ExtractionThreads();
  const int window = options.search_window;

  std::map<int, FrameRecord> frames;  // frames read that the search may still need, by index
  int frames_read = 0;
  bool source_done = false;
  ProgressOptions progress_options;
  progress_options.enabled = options.show_progress;
  ProgressLine progress("build", source.info().expected_frames, "frames", progress_options);
  // Reads frames up to `index`; returns the index of the last frame read (-1 when there is none).
  auto read_until = [&](int index) {
    while (frames_read <= index && !source_done) {
      std::optional<Frame> frame = source.Next();
      if (!frame) {
        source_done = true;
        break;
      }
      FrameRecord record;
      record.frame = std::make_shared<const Frame>(std::move(*frame));
      frames.emplace(frames_read++, std::move(record));
      progress.Update(frames_read);
      if (options.after_frame) options.after_frame();
    }
    return std::min(index, frames_read - 1);
  };

  std::map<std::pair<int, int>, PairComparison> comparisons;  // by (key, frame) index
  std::vector<Evaluation> evaluations;                        // every comparison, in the order made
  auto remember = [&](int key_index, int frame_index, PairComparison comparison) -> const PairComparison& {
    evaluations.push_back({key_index, frame_index, comparison.similarity, comparison.num_tentative,
                           comparison.num_verified, comparison.matched});
    return comparisons[{key_index, frame_index}] = std::move(comparison);
  };
  auto compare = [&](const FrameRecord& key, const FrameRecord& frame) {
    return ComparePair(matcher, *key.features, *frame.features, verifier, options.key_images.similarity, taus);
  };
  auto with_features = [&](int index) -> const FrameRecord& {
    FrameRecord& record = frames.at(index);
    if (!record.features) record.features = matcher.Extract(record.frame->gray);
    return record;
  };
  // Compares the frames at `positions` with the key, one thread each; returns the first that fails (or -1)
  // and moves *last_pass to the last one passing before it.
  auto probe = [&](const FrameRecord& key, const std::vector<int>& positions, int* last_pass) {
    std::vector<std::future<std::pair<std::shared_ptr<const ImageFeatures>, PairComparison>>> results;
    for (int position : positions) {
      if (comparisons.count({key.frame->index, position})) {
        results.emplace_back();
        continue;
      }
      FrameRecord frame = frames.at(position);
      results.push_back(std::async(std::launch::async, [&matcher, &compare, key, frame]() mutable {
        if (!frame.features) frame.features = matcher.Extract(frame.frame->gray);
        return std::make_pair(frame.features, compare(key, frame));
      }));
    }
    for (size_t i = 0; i < positions.size(); ++i) {
      if (!results[i].valid()) continue;
      auto [features, comparison] = results[i].get();
      frames.at(positions[i]).features = std::move(features);
      remember(key.frame->index, positions[i], std::move(comparison));
    }
    for (int position : positions) {
      const PairComparison& c = comparisons.at({key.frame->index, position});
      if (!(c.matched && c.similarity >= options.key_images.tau)) return position;
      *last_pass = position;
    }
    return -1;
  };

  std::unique_ptr<MapWriter> writer;
  if (!directory.empty()) writer = std::make_unique<MapWriter>(directory);
  KeyImageSelector::KeyImageFn on_key_image;
  if (writer) {
    on_key_image = [&writer](const FrameRecord& record, KeyImage& key) {
      key.image_file = writer->AddKeyImage(record.frame);
    };
  }
  KeyImageSelector selector(
      options.key_images,
      [&](const FrameRecord& key, const FrameRecord& frame) {
        const auto it = comparisons.find({key.frame->index, frame.frame->index});
        if (it != comparisons.end()) return it->second;
        return remember(key.frame->index, frame.frame->index, compare(key, frame));
      },
      on_key_image);
  std::unique_ptr<LinkVerifier> link_verifier;
  if (verifier.own_magsac) link_verifier = std::make_unique<LinkVerifier>(VerifierOptions(verifier));

  if (read_until(0) == 0) {
    selector.Add(with_features(0));
    int last_pass = 0, fed = 0, step = 1;
    for (;;) {
      const FrameRecord key = *selector.current_key();
      frames.erase(frames.begin(), frames.lower_bound(last_pass));  // the selector holds the key itself
      // Gallop: offsets step .. 2^(workers - 1) step, at most `window` ahead.
      int first_fail = -1;
      while (first_fail < 0 && read_until(last_pass + 1) > last_pass) {
        const int reach = std::min(window, step << std::min(workers - 1, 20));
        std::vector<int> positions;
        for (int i = 1; i <= workers; ++i) {
          const int position = read_until(last_pass + std::max(1, reach * i / workers));
          if (positions.empty() || position > positions.back()) positions.push_back(position);
        }
        first_fail = probe(key, positions, &last_pass);
        step = std::min(window, 2 * reach);
      }
      if (first_fail < 0) {  // the last frame passes: it is the final key image (Finish)
        if (last_pass > fed) selector.Add(frames.at(last_pass));
        break;
      }
      // Bisect: the frames between the last passing and the first failing frame, split into workers + 1 parts.
      while (first_fail - last_pass > 1) {
        std::vector<int> positions;
        for (int i = 1; i <= workers; ++i) {
          const int position = last_pass + (first_fail - last_pass) * i / (workers + 1);
          if (position > last_pass && position < first_fail && (positions.empty() || position > positions.back())) {
            positions.push_back(position);
          }
        }
        if (positions.empty()) positions.push_back(last_pass + 1);
        const int failing = probe(key, positions, &last_pass);
        if (failing >= 0) first_fail = failing;
      }
      // Algorithm 1 on the frames found: the last passing frame, then the first failing one.
      if (last_pass > fed) selector.Add(frames.at(last_pass));
      selector.Add(with_features(first_fail));
      fed = last_pass = first_fail;
      step = 1;
    }
  }
  progress.Finish();
  selector.Finish();
  if (link_verifier) {
    for (const Link& link : selector.links()) {
      const KeyImage& from = selector.key_images()[link.from_key];
      const KeyImage& to = selector.key_images()[link.to_key];
      link_verifier->Add(from, to, link, options.key_images.similarity,
                         comparisons.at({from.frame_index, to.frame_index}).checkpoint);
    }
    link_verifier->Finish();
  }
  VisualMap map = CollectMap(selector, source, options, options_json, SecondsSince(start), /*analyze_links=*/true,
                             link_verifier.get(), options.key_images.tau);
  map.num_frames = frames_read;
  map.evaluations = std::move(evaluations);
  map.quality = ComputeStatistics(map, options.quality_mean).quality;
  spdlog::debug("bisect search: {} comparisons for {} frames", map.evaluations.size(), map.num_frames);
  if (writer) {
    // The search compares frames out of order and keeps its comparisons anyway (a window's worth): its
    // evaluations go to the writer at the end, in the order made.
    for (const Evaluation& evaluation : map.evaluations) writer->AddEvaluation(evaluation);
    VisualMap written = map;
    written.evaluations.clear();
    writer->Finish(written);
  }
  return map;
}

}  // namespace

VisualMap BuildMap(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                   const fs::path& directory, const std::string& options_json) {
  if (ResolveKeySearch(options) == KeySearch::kBisect) {
    return SearchKeyImages(source, matcher, options, directory, options_json);
  }
  std::vector<VisualMap> maps;
  RunSelectors(source, matcher, options, {options.key_images.tau}, {directory}, &maps, options_json);
  return std::move(maps.front());
}

SweepResult SweepThresholds(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::vector<double>& taus, std::vector<VisualMap>* maps,
                            const fs::path& maps_directory, const std::string& options_json) {
  if (options.key_search == KeySearch::kBisect) {
    throw OptionError("key_search",
                      "bisect looks for each tau's key images on its own; a sweep compares every frame once for all "
                      "taus. Build one map per tau with key_search bisect instead",
                      {"key_search"});
  }
  std::vector<fs::path> directories;
  for (double tau : taus) {
    directories.push_back(maps_directory.empty() ? fs::path() : maps_directory / fmt::format("tau_{:.2f}", tau));
    if (std::count(directories.begin(), directories.end(), directories.back()) > 1 && !maps_directory.empty()) {
      throw InputError(fmt::format("two thresholds round to the same map folder '{}'; the maps are named with two "
                                   "decimals, so give thresholds at least 0.01 apart",
                                   directories.back().filename().string()));
    }
  }
  for (const fs::path& directory : directories) {
    if (!directory.empty()) fs::create_directory(directory);  // inside maps_directory, which must exist
  }
  return RunSelectors(source, matcher, options, taus, directories, maps, options_json);
}

nlohmann::json ToJson(const MapBuilderOptions& options) {
  nlohmann::json record = ToJson(options.key_images);
  record.update(ToJson(options.link_analysis));
  record["verifier"] = ToJson(options.verifier);
  record["exhaustive"] = options.exhaustive;
  record["search"] = KeySearchName(ResolveKeySearch(options));
  record["search_window"] = options.search_window;
  record["quality_mean"] = QualityMeanName(options.quality_mean);
  return record;
}

void FromJson(const JsonFieldReader& fields, MapBuilderOptions* options) {
  FromJson(fields, &options->key_images);
  FromJson(fields, &options->link_analysis);
  FromJson(fields.Object("verifier"), &options->verifier);
  fields.Read("exhaustive", &options->exhaustive);
  fields.Read("search", &options->key_search, kKeySearchNames);
  fields.Read("search_window", &options->search_window);
  fields.Read("quality_mean", &options->quality_mean, kQualityMeanNames);
}

nlohmann::json ToJson(const RecordedOptions& options) {
  nlohmann::json record = ToJson(options.builder);
  record["matcher"] = nlohmann::json::parse(options.matcher_json);
  record["source"] = ToJson(options.source);
  return record;
}

RecordedOptions RecordedOptionsFromJson(const std::string& options_json, const std::string& where) {
  nlohmann::json record;
  try {
    record = nlohmann::json::parse(options_json);
  } catch (const nlohmann::json::exception&) {
    throw InputError(where + " is not valid JSON");
  }
  const JsonFieldReader fields(record, where);
  RecordedOptions options;
  FromJson(fields, &options.builder);
  FromJson(fields.Object("source"), &options.source);
  const JsonFieldReader matcher = fields.Object("matcher");
  matcher.Read("type", &options.matcher_type);
  options.matcher_json = matcher.object().dump();
  return options;
}

}  // namespace vmap
