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
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/progress.h"
#include "vmap/map/map_io.h"

namespace vmap {
namespace fs = std::filesystem;

KeySearch ParseKeySearch(const std::string& name) {
  if (name == "auto") return KeySearch::kAuto;
  if (name == "sequential") return KeySearch::kSequential;
  if (name == "bisect") return KeySearch::kBisect;
  throw InputError("unknown key-image search '" + name + "'; use auto, sequential or bisect");
}

std::string KeySearchName(KeySearch search) {
  switch (search) {
    case KeySearch::kAuto: return "auto";
    case KeySearch::kSequential: return "sequential";
    case KeySearch::kBisect: return "bisect";
  }
  return "auto";
}

KeySearch ResolveKeySearch(const MapBuilderOptions& options) {
  return options.key_search == KeySearch::kAuto ? KeySearch::kSequential : options.key_search;
}

void MapBuilderOptions::Check() const {
  key_images.Check();
  verifier.Check();
  link_analysis.Check();
  if (prefetch_frames < 1 || prefetch_frames > 1024) throw InputError("prefetch_frames must be 1 to 1024");
  if (extraction_threads < 0 || extraction_threads > kMaxExtractionThreads) {
    throw InputError("--threads must be 0 to " + std::to_string(kMaxExtractionThreads) + " (0 = one per core)");
  }
  if (exhaustive && key_search == KeySearch::kBisect) {
    throw InputError("--exhaustive is the paper's frame-by-frame scan and --search bisect skips frames; drop one");
  }
  if (search_window < 2 || search_window > 4096) {
    throw InputError("--search-window must be 2 to 4096 frames (default 32)");
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

// Decodes frames on one thread and, on `workers` threads, extracts their features and compares them with
// the current key images, a few frames ahead of the consumer, which receives them in order.
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
  FeaturePipeline(FrameSource& source, const Matcher& matcher, int depth, int workers, CompareFn compare)
      : source_(source), matcher_(matcher), compare_(std::move(compare)), depth_(std::max(depth, workers + 1)) {
    try {
      reader_ = std::thread([this] { Guard([this] { ReadFrames(); }); });
      for (int i = 0; i < workers; ++i) workers_.emplace_back([this] { Guard([this] { ExtractFeatures(); }); });
    } catch (const std::system_error& error) {
      // The system refused a thread (a process limit): stop those already started, or their destructors abort.
      Stop();
      throw InputError("cannot start " + std::to_string(workers + 1) + " threads (" + error.what() +
                       "); use fewer with --threads");
    }
  }

  ~FeaturePipeline() { Stop(); }

  // The key images (distinct) that frames extracted from now on are compared with, each with the thresholds
  // of the selectors holding it: a frame below the lowest makes all of them leave the key.
  void SetCurrentKeys(std::vector<CurrentKey> keys) {
    auto shared = std::make_shared<const std::vector<CurrentKey>>(std::move(keys));
    std::lock_guard<std::mutex> lock(mutex_);
    current_keys_ = std::move(shared);
  }

  // The next frame, or nullopt at the end. Rethrows a worker's error.
  std::optional<PipelineItem> Next() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return error_ || ready_.count(next_out_) || AllDone(); });
    if (error_) std::rethrow_exception(error_);
    auto it = ready_.find(next_out_);
    if (it == ready_.end()) return std::nullopt;
    PipelineItem item = std::move(it->second);
    ready_.erase(it);
    ++next_out_;
    // A successor is a frame at most a pipeline's depth behind the consumer; keep a margin.
    recent_.erase(recent_.begin(), recent_.lower_bound(static_cast<int>(next_out_) - 2 * depth_));
    changed_.notify_all();
    return item;
  }

  long extracted() const { return extracted_; }

 private:
  // Runs a thread's work; an exception stops the pipeline and reaches the consumer.
  template <typename Fn>
  void Guard(Fn&& work) {
    try {
      work();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      stop_ = true;
      changed_.notify_all();
    }
  }

  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    if (reader_.joinable()) reader_.join();
    for (std::thread& worker : workers_) worker.join();
  }

  int InFlight() const { return static_cast<int>(decoded_.size() + ready_.size()) + extracting_; }
  bool AllDone() const { return reader_done_ && decoded_.empty() && extracting_ == 0; }

  void ReadFrames() {
    for (long sequence = 0;; ++sequence) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return stop_ || InFlight() < depth_; });
        if (stop_) break;
      }
      std::optional<Frame> frame = source_.Next();
      std::lock_guard<std::mutex> lock(mutex_);
      if (!frame) break;
      decoded_.emplace_back(sequence, std::move(*frame));
      changed_.notify_all();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    reader_done_ = true;
    changed_.notify_all();
  }

  void ExtractFeatures() {
    for (;;) {
      std::pair<long, Frame> decoded;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return stop_ || !decoded_.empty() || reader_done_; });
        if (stop_ || decoded_.empty()) return;
        decoded = std::move(decoded_.front());
        decoded_.pop_front();
        ++extracting_;
      }
      PipelineItem item;
      const Frame& frame = decoded.second;
      item.record.features = RethrowAsInputError(
          [&] {
            return ErrorContext{"the " + matcher_.name() + " matcher failed on frame " +
                                    std::to_string(frame.source_index) + " (" + frame.source_name + ")",
                                "check the frame, or try other matcher options"};
          },
          [&] { return matcher_.Extract(frame.gray); });
      item.record.frame = std::make_shared<const Frame>(std::move(decoded.second));
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
        PairComparison comparison =
            compare_(group.record, item.record, group.taus, [this, key_index, frame_index, &group] {
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
      std::lock_guard<std::mutex> lock(mutex_);
      --extracting_;
      ready_.emplace(decoded.first, std::move(item));
      changed_.notify_all();
    }
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
  // or a higher threshold leave it here at the latest, for the previous frame (or this one when the previous
  // is the key: a link below tau).
  void Retire(int key_index, int frame_index, double tau) {
    const int successor = frame_index - 1 == key_index ? frame_index : frame_index - 1;
    std::lock_guard<std::mutex> lock(mutex_);
    retired_[key_index].push_back(Retirement{frame_index, tau, successor});
  }

  FrameSource& source_;
  const Matcher& matcher_;
  const CompareFn compare_;
  const int depth_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::shared_ptr<const std::vector<CurrentKey>> current_keys_;
  struct Retirement {
    int at_frame;    // a frame seen to fall below from_tau against the key
    double from_tau;  // the lowest threshold it fell below: selectors with this tau or a higher one leave
    int successor;   // the frame that replaces the key for them
  };
  std::map<int, std::vector<Retirement>> retired_;  // by key frame index
  std::map<int, FrameRecord> recent_;    // extracted frames a successor may be taken from, by frame index
  std::deque<std::pair<long, Frame>> decoded_;  // read, waiting for a worker
  std::map<long, PipelineItem> ready_;          // extracted, waiting for the consumer
  int extracting_ = 0;
  long next_out_ = 0;
  bool reader_done_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
  std::atomic<long> extracted_{0};
  std::thread reader_;
  std::vector<std::thread> workers_;
};

// A key image is the input's own file when the frame was decoded from an image file at its size: a copy costs
// ~0.1 ms and is exactly the input. Other frames (video, resized) are written as PNG with OpenCV's default
// settings (zlib level 1, run-length strategy): measured 2x faster than level 1 with the default strategy, for
// files 15 % larger; still ~10 ms for 640x480, hence the thread of its own.
// Only PNG and JPEG files are kept as they are, and only when their header gives the frame's size: ReadMap
// checks a key image's size from those headers.
bool KeepsSourceFile(const Frame& frame) {
  if (frame.source_path.empty() || frame.resized) return false;
  std::string extension = fs::path(frame.source_path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension != ".png" && extension != ".jpg" && extension != ".jpeg") return false;
  // A JPEG whose EXIF orientation turned it when decoded has another size in its header than the frame: a copy
  // would not be the frame ReadMap expects.
  const std::optional<cv::Size> size = KeyImageFileSize(frame.source_path);
  return size && *size == frame.gray.size();
}

std::string KeyImageFileName(const Frame& frame) {
  std::string extension = ".png";
  if (KeepsSourceFile(frame)) {
    extension = fs::path(frame.source_path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  }
  return fmt::format("keys/{:06d}{}", frame.index, extension);
}

// Writes key images on a thread of its own, so that encoding never stalls the consumer, and with it the
// whole pipeline.
class KeyImageFileWriter {
 public:
  KeyImageFileWriter() : thread_([this] { Run(); }) {}
  // Never throws: when the build failed, a write error no longer matters.
  ~KeyImageFileWriter() { Join(); }

  // A callback for KeyImageSelector that writes each key image into directory/keys/; null without a directory.
  KeyImageSelector::KeyImageFn CallbackFor(const fs::path& directory) {
    if (directory.empty()) return nullptr;
    // Not create_directories: `directory` is or lies in a temporary output, and once an interruption has
    // removed that, nothing may bring it back (AtomicOutputDirectory::path()). It must exist.
    fs::create_directory(directory / "keys");
    return [this, directory](const FrameRecord& record, KeyImage& key) {
      key.image_file = KeyImageFileName(*record.frame);
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.emplace_back(directory / key.image_file, record.frame);
      changed_.notify_all();
    };
  }

  // Waits for every image to be written; rethrows the first failure.
  void Finish() {
    Join();
    if (error_) std::rethrow_exception(error_);
  }

 private:
  void Join() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  void Run() {
    for (;;) {
      std::pair<fs::path, std::shared_ptr<const Frame>> job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return finished_ || !queue_.empty(); });
        if (queue_.empty()) return;
        job = std::move(queue_.front());
        queue_.pop_front();
      }
      if (error_) continue;
      const Frame& frame = *job.second;
      std::error_code copy_error;
      const bool written =
          KeepsSourceFile(frame)
              ? fs::copy_file(frame.source_path, job.first, fs::copy_options::overwrite_existing, copy_error)
              : cv::imwrite(job.first.string(), ColorImage(frame));
      if (!written) {
        error_ = std::make_exception_ptr(InputError("cannot write key image '" + job.first.string() + "'" +
                                                    (copy_error ? ": " + copy_error.message() : std::string())));
      }
    }
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::pair<fs::path, std::shared_ptr<const Frame>>> queue_;
  bool finished_ = false;
  std::exception_ptr error_;  // written by the thread, read after join
  std::thread thread_;        // last: starts after every other member exists
};

// Verifies links in full, on a thread of its own while the build goes on, when the decisions stopped early:
// the tables are then computed from exact link values. The estimator runs again on the link's own tentative
// matches (no matching, no features kept). A link shared by several taus (same two frames) is verified once.
class LinkVerifier {
 public:
  explicit LinkVerifier(const VerifierOptions& verifier) : verifier_(verifier), thread_([this] { Run(); }) {}
  ~LinkVerifier() { Join(); }

  // Queues `link`, between key images `from` and `to`, unless that pair of frames is queued already.
  void Add(const KeyImage& from, const KeyImage& to, const Link& link, SimilarityMode similarity) {
    const auto pair = std::make_pair(from.frame_index, to.frame_index);
    Job job;
    for (const Correspondence& c : link.correspondences) {
      job.matches.points0.push_back(c.p0);
      job.matches.points1.push_back(c.p1);
    }
    job.denominator = similarity == SimilarityMode::kInlierRatio ? link.num_tentative
                                                                 : std::max(from.num_features, to.num_features);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!results_.emplace(pair, PairComparison{}).second) return;
    job.pair = pair;
    queue_.push_back(std::move(job));
    changed_.notify_all();
  }

  // Waits for every verification; rethrows a failure. Returns how many links were verified.
  long Finish() {
    Join();
    if (error_) std::rethrow_exception(error_);
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
  struct Job {
    std::pair<int, int> pair;
    TentativeMatches matches;
    int denominator = 0;
  };

  void Join() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  void Run() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return finished_ || !queue_.empty(); });
        if (queue_.empty()) return;
        job = std::move(queue_.front());
        queue_.pop_front();
      }
      if (error_) continue;
      try {
        PairComparison verified = VerifyMatches(job.matches, job.denominator, verifier_);
        std::lock_guard<std::mutex> lock(mutex_);
        results_[job.pair] = std::move(verified);
      } catch (...) {
        error_ = std::current_exception();
      }
    }
  }

  const VerifierOptions verifier_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> queue_;
  std::map<std::pair<int, int>, PairComparison> results_;  // by (from, to) frame index
  bool finished_ = false;
  std::exception_ptr error_;  // written by the thread, read after join
  std::thread thread_;        // last: starts after every other member exists
};

// `link_verifier` (when the decisions stopped early): the links verified in full replace the deciding ones.
// `analyze_links`: also each link's pose, parallax and homography test (only maps that are kept need them).
VisualMap CollectMap(const KeyImageSelector& selector, const FrameSource& source, const MapBuilderOptions& options,
                     const std::string& options_json, double seconds, bool analyze_links,
                     const LinkVerifier* link_verifier = nullptr, double tau = 0.0) {
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
  AnalyzeLinks(map, options.link_analysis, options.ExtractionThreads());
  const double analysis_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - analysis_start).count();
  spdlog::debug("pose, parallax and homography test of {} links in {:.3f} s", map.links.size(), analysis_seconds);
  map.seconds += analysis_seconds;  // part of building the map
  return map;
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
      throw InputError("--thresholds '" + text + "' must be start:stop:step with step > 0 and stop >= start");
    }
    // Count steps with a tolerance so that 0.1:0.9:0.1 includes 0.9; counted in double before anything is
    // allocated, so that a tiny step is refused rather than filling the memory.
    const double count = std::floor((stop - start) / step + 1e-9) + 1;
    if (count > kMaxThresholds) {
      throw InputError(fmt::format("--thresholds '{}' gives {:.0f} thresholds, more than {}; use a larger step",
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
        throw InputError("--thresholds '" + text + "' is not start:stop:step (0.1:0.9:0.1) or a list (0.2,0.5)");
      }
      if (taus.size() > kMaxThresholds) {
        throw InputError("--thresholds '" + text + "' lists more than " + std::to_string(kMaxThresholds) + " thresholds");
      }
    }
  }
  if (taus.empty()) throw InputError("--thresholds '" + text + "' gives no threshold");
  for (size_t i = 0; i < taus.size(); ++i) {
    KeyImageOptions check;
    check.tau = taus[i];
    check.Check();
    for (size_t j = 0; j < i; ++j) {
      if (taus[j] == taus[i]) throw InputError(fmt::format("--thresholds '{}' gives tau = {} twice", text, taus[i]));
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

// Runs one selector per tau over one pass of the source; directories[i] receives tau i's key images.
SweepResult RunSelectors(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                         const std::vector<double>& taus, const std::vector<fs::path>& directories,
                         std::vector<VisualMap>* maps, const std::string& options_json) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  SweepResult result;
  result.options_json = options_json;

  const VerifierOptions verifier = DecisionVerifier(options);
  const bool stops_early = verifier.own_magsac;
  std::atomic<long> pairs_matched{0}, pairs_abandoned{0};
  const CompareFn compare_pair = [&](const FrameRecord& key, const FrameRecord& frame,
                                     const std::vector<double>& decide_taus, const std::function<bool()>& abandon) {
    ++pairs_matched;
    PairComparison comparison = RethrowAsInputError(
        [&] {
          return ErrorContext{"matching frame " + std::to_string(frame.frame->source_index) + " (" +
                                  frame.frame->source_name + ") with key image " +
                                  std::to_string(key.frame->source_index) + " (" + key.frame->source_name + ") failed",
                              "check the frames, or try other matcher or verifier options"};
        },
        [&] {
          return ComparePair(matcher, *key.features, *frame.features, verifier, options.key_images.similarity,
                             stops_early ? decide_taus : std::vector<double>{}, abandon);
        });
    if (comparison.abandoned) ++pairs_abandoned;
    return comparison;
  };
  // The comparisons of the current frame, by key frame: made ahead by the pipeline, or here when a key image
  // changed meanwhile or a comparison that stopped early does not answer a selector's tau. A pair compared
  // under several taus is matched once.
  std::map<int, PairComparison>* comparisons_of_frame = nullptr;
  std::map<int, std::vector<double>> holders;  // key frame index -> taus of the selectors holding it
  auto compare_for = [&](double tau) -> KeyImageSelector::CompareFn {
    return [&, tau](const FrameRecord& key, const FrameRecord& frame) -> PairComparison {
      const int key_index = key.frame->index;
      auto it = comparisons_of_frame->find(key_index);
      if (it != comparisons_of_frame->end() && it->second.Decides(tau)) return it->second;
      // Settle at once what the other selectors that may ask will need: the holders of the key, or every tau
      // for a key just chosen (they follow from the same failing frame) or asked again.
      const auto held = holders.find(key_index);
      std::vector<double> asked = it == comparisons_of_frame->end() && held != holders.end() ? held->second : taus;
      if (std::find(asked.begin(), asked.end(), tau) == asked.end()) asked.push_back(tau);
      return (*comparisons_of_frame)[key_index] = compare_pair(key, frame, asked, nullptr);
    };
  };
  KeyImageFileWriter image_writer;
  std::vector<std::unique_ptr<KeyImageSelector>> selectors;
  for (size_t i = 0; i < taus.size(); ++i) {
    KeyImageOptions key_options = options.key_images;
    key_options.tau = taus[i];
    selectors.push_back(
        std::make_unique<KeyImageSelector>(key_options, compare_for(taus[i]), image_writer.CallbackFor(directories[i])));
  }
  // Links keep a full estimation when the decisions stopped early; queued as soon as each link is made.
  std::unique_ptr<LinkVerifier> link_verifier;
  if (stops_early) link_verifier = std::make_unique<LinkVerifier>(VerifierOptions(verifier));
  std::vector<size_t> links_queued(selectors.size(), 0);
  auto queue_new_links = [&] {
    if (!link_verifier) return;
    for (size_t i = 0; i < selectors.size(); ++i) {
      const KeyImageSelector& selector = *selectors[i];
      for (; links_queued[i] < selector.links().size(); ++links_queued[i]) {
        const Link& link = selector.links()[links_queued[i]];
        link_verifier->Add(selector.key_images()[link.from_key], selector.key_images()[link.to_key], link,
                           options.key_images.similarity);
      }
    }
  };

  {
    FeaturePipeline pipeline(source, matcher, options.prefetch_frames, options.ExtractionThreads(), compare_pair);
    ProgressOptions progress_options;
    progress_options.enabled = options.show_progress;
    ProgressLine progress(taus.size() == 1 ? "build" : "sweep", source.info().expected_frames, "frames",
                          progress_options);
    long done = 0;
    while (std::optional<PipelineItem> item = pipeline.Next()) {
      comparisons_of_frame = &item->comparisons;
      for (auto& selector : selectors) selector->Add(item->record);
      queue_new_links();
      // Tell the workers which key images the coming frames will be compared with (a handful of
      // shared pointers: cheaper to publish every frame than to track changes).
      std::map<int, CurrentKey> keys;  // by key frame index
      for (size_t i = 0; i < selectors.size(); ++i) {
        const FrameRecord* key = selectors[i]->current_key();
        if (!key) continue;
        keys.emplace(key->frame->index, CurrentKey{*key, {}}).first->second.taus.push_back(taus[i]);
      }
      holders.clear();
      std::vector<CurrentKey> current;
      for (auto& [index, key] : keys) {
        std::sort(key.taus.begin(), key.taus.end());
        holders[index] = key.taus;
        current.push_back(std::move(key));
      }
      pipeline.SetCurrentKeys(std::move(current));
      progress.Update(++done);
    }
    progress.Finish();
    result.features_extracted = pipeline.extracted();
  }
  for (auto& selector : selectors) selector->Finish();  // the final key images
  queue_new_links();
  image_writer.Finish();
  result.pairs_matched = pairs_matched;
  long evaluations = 0;
  for (const auto& selector : selectors) evaluations += static_cast<long>(selector->evaluations().size());
  if (link_verifier) result.links_verified = link_verifier->Finish();
  spdlog::debug("{} pairs matched and verified for {} evaluations, {} abandoned; {} links verified in full",
                result.pairs_matched, evaluations, pairs_abandoned.load(), result.links_verified);

  const double seconds = SecondsSince(start);
  result.input = source.info();
  result.seconds = seconds;
  for (size_t i = 0; i < selectors.size(); ++i) {
    VisualMap map = CollectMap(*selectors[i], source, options, options_json, seconds, maps != nullptr,
                               link_verifier.get(), taus[i]);
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

  KeyImageFileWriter image_writer;
  KeyImageSelector selector(
      options.key_images,
      [&](const FrameRecord& key, const FrameRecord& frame) {
        const auto it = comparisons.find({key.frame->index, frame.frame->index});
        if (it != comparisons.end()) return it->second;
        return remember(key.frame->index, frame.frame->index, compare(key, frame));
      },
      image_writer.CallbackFor(directory));
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
  image_writer.Finish();
  if (link_verifier) {
    for (const Link& link : selector.links()) {
      link_verifier->Add(selector.key_images()[link.from_key], selector.key_images()[link.to_key], link,
                         options.key_images.similarity);
    }
    link_verifier->Finish();
  }
  VisualMap map = CollectMap(selector, source, options, options_json, SecondsSince(start), /*analyze_links=*/true,
                             link_verifier.get(), options.key_images.tau);
  map.num_frames = frames_read;
  map.evaluations = std::move(evaluations);
  map.quality = ComputeStatistics(map, options.quality_mean).quality;
  spdlog::debug("bisect search: {} comparisons for {} frames", map.evaluations.size(), map.num_frames);
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
    throw InputError("--search bisect looks for each tau's key images on its own; a sweep compares every frame "
                     "once for all taus. Run `vmap build --tau T --search bisect` per tau instead");
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

}  // namespace vmap
