#include "vmap/mapping/map_builder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <optional>

#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/progress.h"
#include "vmap/core/stopwatch.h"
#include "vmap/map/map_writer.h"
#include "vmap/mapping/collect_map.h"
#include "vmap/mapping/feature_pipeline.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/mapping/link_analysis.h"
#include "vmap/mapping/link_verifier.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap {
namespace {

std::vector<double> Sorted(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values;
}

// The record of each tau's map: the options given, at that tau (a sweep's maps each record their own).
std::vector<std::string> RecordedAtEachTau(const std::string& options_json, const std::vector<double>& taus) {
  std::vector<std::string> recorded;
  for (const double tau : taus) recorded.push_back(RecordedAtTau(options_json, tau));
  return recorded;
}

}  // namespace

// The streaming state of a build: the pipeline, one selector per tau, the link verifier and the sinks.
class MapBuilder::Impl {
 public:
  Impl(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options, std::vector<double> taus,
       std::vector<MapWriter*> writers, std::string options_json)
      : source_(source),
        matcher_(matcher),
        options_(options),
        taus_(std::move(taus)),
        sorted_taus_(Sorted(taus_)),
        writers_(std::move(writers)),
        options_json_(RecordedAtEachTau(options_json, taus_)),
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
      selectors_.push_back(std::make_unique<KeyImageSelector>(key_options, std::move(on_key_image),
                                                              std::move(on_evaluation), std::move(on_link)));
    }
    if (stops_early_) link_verifier_ = std::make_unique<LinkVerifier>(VerifierOptions(verifier_));
    link_analyses_.resize(selectors_.size());
    pipeline_ = std::make_unique<FeaturePipeline>(matcher, options_.prefetch_frames, options_.ExtractionThreads(),
                                                  compare_pair_, sorted_taus_);
  }

  void Add(Frame frame) {
    if (finished_) throw std::logic_error("MapBuilder::Add after Finish");
    if (first_source_index_ < 0) first_source_index_ = frame.source_index;
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
      VisualMap map =
          CollectMap(*selectors_[i], source_, matcher_, options_, options_json_[i], SecondsSince(start_),
                     /*analyze_links=*/true, link_verifier_.get(), taus_[i], &link_analyses_[i], writers_[i]);
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
    // A map of no key image is no map: no command could read it (whatever the input, this is an error).
    if (first_source_index_ < 0) ThrowNoFrameUsed(source_);
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
    // The links' pose tests (and their cross-check on denser features) may take longer than the frames did: a line
    // of their own, so that the frames' 100 % is not followed by silence.
    long links = 0;
    for (const auto& selector : selectors_) links += std::max(0L, static_cast<long>(selector->key_images().size()) - 1);
    ProgressLine link_progress(selectors_.size() == 1 ? "links" : "sweep links", analyze_links ? links : 0, "links",
                               ProgressOptions{options_.show_progress && analyze_links});
    long links_done = 0;
    const auto link_done = [&] { link_progress.Update(++links_done); };
    std::vector<VisualMap> maps;
    for (size_t i = 0; i < selectors_.size(); ++i) {
      VisualMap map = CollectMap(*selectors_[i], source_, matcher_, options_, options_json_[i], seconds, analyze_links,
                                 link_verifier_.get(), taus_[i], &link_analyses_[i], writers_[i], link_done);
      // A map of a whole file says nothing more (its map.json stays as it was); a live input's says what it
      // covers.
      if (end != CoverageEnd::kInputEnded || source_.info().expected_frames < 0) map.coverage = CurrentCoverage(end);
      if (writers_[i]) writers_[i]->Finish(map, with_evaluations ? &map.evaluations : nullptr);
      maps.push_back(std::move(map));
    }
    link_progress.Finish();
    return maps;
  }

  long features_extracted() const { return features_extracted_; }
  long pairs_matched() const { return pairs_matched_; }
  long links_verified() const { return links_verified_; }
  double seconds() const { return SecondsSince(start_); }

 private:
  // The comparisons of a frame for the selector with threshold `tau`, from `comparisons` (the frame's, by key frame):
  // made ahead by the pipeline, or here when a key image changed meanwhile. A pair compared under several taus is
  // matched once. A comparison that stopped early is used only when it settled exactly ThresholdsToSettle: the workers
  // guess which selectors will hold a key image, and a comparison made for another set could give another S, and
  // another decision (before this, a sweep could give other tables from one run to the next).
  KeyImageSelector::CompareFn CompareFor(double tau, std::map<int, PairComparison>& comparisons) {
    return [this, tau, &comparisons](const FrameRecord& key, const FrameRecord& frame) -> PairComparison {
      const int key_index = key.frame->index;
      const auto held = holders_.find(key_index);
      const std::vector<double> asked = ThresholdsToSettle(
          key_index, frame.frame->index, held != holders_.end() ? &held->second : nullptr, sorted_taus_, tau);
      auto it = comparisons.find(key_index);
      if (it != comparisons.end() && (it->second.exhaustive || it->second.decided_taus == asked)) {
        return it->second;
      }
      return comparisons[key_index] = compare_pair_(key, frame, asked, nullptr);
    };
  }

  void Process(PipelineItem& item) {
    // A snapshot covers the frames processed, not those still in flight.
    last_source_index_ = item.record.frame->source_index;
    for (size_t i = 0; i < selectors_.size(); ++i) {
      selectors_[i]->Add(item.record, CompareFor(taus_[i], item.comparisons));
    }
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
  const Matcher& matcher_;
  const MapBuilderOptions options_;
  const std::vector<double> taus_;  // selector i's is taus_[i]
  const std::vector<double> sorted_taus_;
  std::vector<MapWriter*> writers_;
  const std::vector<std::string> options_json_;  // each tau's map's record of its options
  const std::chrono::steady_clock::time_point start_;
  const VerifierOptions verifier_;
  const bool stops_early_;
  ProgressLine progress_;
  CompareForTausFn compare_pair_;
  std::atomic<long> pairs_matched_{0}, pairs_abandoned_{0};
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
  impl_ =
      std::make_unique<Impl>(source, matcher, options, std::move(taus), std::move(writers), std::move(options_json));
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

}  // namespace vmap
