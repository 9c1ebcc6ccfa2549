#include "vmap/mapping/map_builder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/progress.h"

namespace vmap {
namespace fs = std::filesystem;

void MapBuilderOptions::Check() const {
  key_images.Check();
  verifier.Check();
  link_analysis.Check();
  if (prefetch_frames < 1 || prefetch_frames > 1024) throw InputError("prefetch_frames must be 1 to 1024");
  if (extraction_threads < 0 || extraction_threads > kMaxExtractionThreads) {
    throw InputError("--threads must be 0 to " + std::to_string(kMaxExtractionThreads) + " (0 = one per core)");
  }
}

int MapBuilderOptions::ExtractionThreads() const {
  if (extraction_threads > 0) return extraction_threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

namespace {

using CompareFn = std::function<PairComparison(const FrameRecord& key, const FrameRecord& frame)>;

// A key image the workers compare frames with, and the lowest tau of the selectors that hold it.
struct CurrentKey {
  FrameRecord record;
  double min_tau = 1.0;
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
// Key changes are followed by the workers too. A key image is retired as soon as a worker sees a frame j
// fail against it: every selector holding it leaves it at frame j at the latest, for frame j-1 (or for j
// itself when j-1 is that key: a link below tau). Frame j and the later ones are compared with that successor
// at once, as the consumer will ask, instead of with the old key at low S, where MAGSAC needs the most
// iterations (up to 60 ms a pair on lab_floor) only for the result to be thrown away, and the consumer then
// redoing the comparisons one by one while the workers wait.
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

  // The key images (distinct) that frames extracted from now on are compared with, each with the lowest
  // tau of the selectors holding it: a frame below that similarity makes all of them leave the key.
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
      if (keys) {
        for (const CurrentKey& current : *keys) {
          // Compare as the consumer will: with the key, with its successor when the frame fails against
          // it (or when an earlier frame turns out to have failed meanwhile), and so on, until the key in
          // force is one already compared, the frame itself, or a successor not extracted yet (the consumer
          // then compares).
          for (;;) {
            const std::optional<FrameRecord> key = ResolveKey(current.record, frame_index);
            if (!key) break;
            const int key_index = key->frame->index;
            if (key_index == frame_index || item.comparisons.count(key_index)) break;
            const PairComparison& comparison =
                item.comparisons.emplace(key_index, compare_(*key, item.record)).first->second;
            if (!comparison.matched || comparison.similarity < current.min_tau) Retire(key_index, frame_index);
          }
        }
      }
      std::lock_guard<std::mutex> lock(mutex_);
      --extracting_;
      ready_.emplace(decoded.first, std::move(item));
      changed_.notify_all();
    }
  }

  // The key image `frame_index` is to be compared with next, as far as the workers know: `key`, or the
  // successor of a key that this frame or an earlier one failed against. Nullopt when that successor is not
  // extracted yet.
  std::optional<FrameRecord> ResolveKey(const FrameRecord& key, int frame_index) {
    std::lock_guard<std::mutex> lock(mutex_);
    int index = key.frame->index;
    for (auto it = retired_.find(index); it != retired_.end() && it->second.at_frame <= frame_index;
         it = retired_.find(index)) {
      index = it->second.successor;
    }
    if (index == key.frame->index) return key;
    auto record = recent_.find(index);
    if (record == recent_.end()) return std::nullopt;
    return record->second;
  }

  // Frame `frame_index` failed against the key image `key_index`.
  void Retire(int key_index, int frame_index) {
    const int successor = frame_index - 1 == key_index ? frame_index : frame_index - 1;
    std::lock_guard<std::mutex> lock(mutex_);
    auto [it, inserted] = retired_.emplace(key_index, Retirement{frame_index, successor});
    if (!inserted && frame_index < it->second.at_frame) it->second = Retirement{frame_index, successor};
  }

  FrameSource& source_;
  const Matcher& matcher_;
  const CompareFn compare_;
  const int depth_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::shared_ptr<const std::vector<CurrentKey>> current_keys_;
  struct Retirement {
    int at_frame;   // the first frame seen to fail against the key
    int successor;  // the frame that replaces the key
  };
  std::map<int, Retirement> retired_;    // by key frame index
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

std::string KeyImageFileName(int frame_index) { return fmt::format("keys/{:06d}.png", frame_index); }

// Writes key images on a thread of its own: PNG encoding (~20 ms per 640x480 image) would otherwise stall
// the consumer, and with it the whole pipeline.
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
      key.image_file = KeyImageFileName(key.frame_index);
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
      // Fast PNG compression: lossless key images at little cost.
      if (!cv::imwrite(job.first.string(), ColorImage(*job.second), {cv::IMWRITE_PNG_COMPRESSION, 1})) {
        error_ = std::make_exception_ptr(InputError("cannot write key image '" + job.first.string() + "'"));
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

// `analyze_links`: also each link's pose, parallax and homography test (only maps that are kept need them).
VisualMap CollectMap(const KeyImageSelector& selector, const FrameSource& source, const MapBuilderOptions& options,
                     const std::string& options_json, double seconds, bool analyze_links) {
  VisualMap map;
  map.input = source.info();
  map.options_json = options_json;
  map.num_frames = selector.num_frames();
  map.skipped_frames = source.skipped_frames();
  map.key_images = selector.key_images();
  map.links = selector.links();
  map.evaluations = selector.evaluations();
  map.seconds = seconds;
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

// Runs one selector per tau over one pass of the source; directories[i] receives tau i's key images.
SweepResult RunSelectors(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                         const std::vector<double>& taus, const std::vector<fs::path>& directories,
                         std::vector<VisualMap>* maps, const std::string& options_json) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  SweepResult result;
  result.options_json = options_json;

  std::atomic<long> pairs_matched{0};
  const CompareFn compare_pair = [&](const FrameRecord& key, const FrameRecord& frame) {
    ++pairs_matched;
    return RethrowAsInputError(
        [&] {
          return ErrorContext{"matching frame " + std::to_string(frame.frame->source_index) + " (" +
                                  frame.frame->source_name + ") with key image " +
                                  std::to_string(key.frame->source_index) + " (" + key.frame->source_name + ") failed",
                              "check the frames, or try other matcher or verifier options"};
        },
        [&] {
          return ComparePair(matcher, *key.features, *frame.features, options.verifier, options.key_images.similarity);
        });
  };
  // The comparisons of the current frame, by key frame: made ahead by the pipeline, or here when a key
  // image changed meanwhile. A pair compared under several taus is matched once.
  std::map<int, PairComparison>* comparisons_of_frame = nullptr;
  auto compare = [&](const FrameRecord& key, const FrameRecord& frame) -> PairComparison {
    auto it = comparisons_of_frame->find(key.frame->index);
    if (it == comparisons_of_frame->end()) {
      it = comparisons_of_frame->emplace(key.frame->index, compare_pair(key, frame)).first;
    }
    return it->second;
  };

  KeyImageFileWriter image_writer;
  std::vector<std::unique_ptr<KeyImageSelector>> selectors;
  for (size_t i = 0; i < taus.size(); ++i) {
    KeyImageOptions key_options = options.key_images;
    key_options.tau = taus[i];
    selectors.push_back(
        std::make_unique<KeyImageSelector>(key_options, compare, image_writer.CallbackFor(directories[i])));
  }

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
      // Tell the workers which key images the coming frames will be compared with (a handful of
      // shared pointers: cheaper to publish every frame than to track changes).
      std::map<int, CurrentKey> keys;  // by key frame index
      for (size_t i = 0; i < selectors.size(); ++i) {
        const FrameRecord* key = selectors[i]->current_key();
        if (!key) continue;
        auto [it, inserted] = keys.emplace(key->frame->index, CurrentKey{*key, taus[i]});
        if (!inserted) it->second.min_tau = std::min(it->second.min_tau, taus[i]);
      }
      std::vector<CurrentKey> current;
      for (auto& [index, key] : keys) current.push_back(std::move(key));
      pipeline.SetCurrentKeys(std::move(current));
      progress.Update(++done);
    }
    progress.Finish();
    result.features_extracted = pipeline.extracted();
  }
  result.pairs_matched = pairs_matched;
  for (auto& selector : selectors) selector->Finish();  // the final key images
  image_writer.Finish();

  const double seconds = SecondsSince(start);
  result.input = source.info();
  result.seconds = seconds;
  for (size_t i = 0; i < selectors.size(); ++i) {
    VisualMap map = CollectMap(*selectors[i], source, options, options_json, seconds, maps != nullptr);
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

}  // namespace

VisualMap BuildMap(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                   const fs::path& directory, const std::string& options_json) {
  std::vector<VisualMap> maps;
  RunSelectors(source, matcher, options, {options.key_images.tau}, {directory}, &maps, options_json);
  return std::move(maps.front());
}

SweepResult SweepThresholds(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::vector<double>& taus, std::vector<VisualMap>* maps,
                            const fs::path& maps_directory, const std::string& options_json) {
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
