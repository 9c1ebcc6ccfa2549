#include "vmap/mapping/feature_pipeline.h"

#include <algorithm>
#include <string>

#include "vmap/core/error.h"

namespace vmap {

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

FeaturePipeline::FeaturePipeline(const Matcher& matcher, int depth, int workers, CompareForTausFn compare,
                                 std::vector<double> all_taus)
    : matcher_(matcher),
      compare_(std::move(compare)),
      all_taus_(std::move(all_taus)),
      depth_(std::max(depth, workers + 1)),
      frames_(depth_, workers, [this](Frame decoded) { return ExtractAndCompare(std::move(decoded)); }) {}

FeaturePipeline::~FeaturePipeline() = default;

bool FeaturePipeline::TryPush(Frame& frame) { return frames_.TryPush(frame); }

void FeaturePipeline::Close() { frames_.Close(); }

void FeaturePipeline::SetCurrentKeys(std::vector<CurrentKey> keys) {
  auto shared = std::make_shared<const std::vector<CurrentKey>>(std::move(keys));
  std::lock_guard<std::mutex> lock(mutex_);
  current_keys_ = std::move(shared);
}

std::optional<PipelineItem> FeaturePipeline::Next() { return Took(frames_.Next()); }

std::optional<PipelineItem> FeaturePipeline::TryNext() { return Took(frames_.TryNext()); }

std::optional<PipelineItem> FeaturePipeline::Took(std::optional<PipelineItem> item) {
  if (!item) return item;
  // A successor is a frame at most a pipeline's depth behind the consumer; keep a margin.
  std::lock_guard<std::mutex> lock(mutex_);
  recent_.erase(recent_.begin(), recent_.lower_bound(static_cast<int>(frames_.taken()) - 2 * depth_));
  return item;
}

PipelineItem FeaturePipeline::ExtractAndCompare(Frame decoded) {
  PipelineItem item;
  item.record.features = RethrowAsInputError(
      [&] {
        return ErrorContext{"the " + matcher_.name() + " matcher failed on frame " +
                                std::to_string(decoded.source_index) + " (" + decoded.source_name + ")",
                            "check the frame, or try other matcher options"};
      },
      [&] { return matcher_.ExtractFrame(decoded.gray, decoded.color); });
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
    PairComparison comparison = compare_(group.record, item.record, asked, [this, key_index, frame_index, &group] {
      std::lock_guard<std::mutex> lock(mutex_);
      for (double tau : group.taus) {
        if (ResolveKey(key_index, tau, frame_index - 1) == key_index) return false;
      }
      return true;
    });
    if (comparison.abandoned) continue;
    for (double tau : group.taus) {
      if (!comparison.Reaches(tau)) {
        Retire(key_index, frame_index, tau);  // this tau and every higher one leave the key here
        break;
      }
    }
    item.comparisons.emplace(key_index, std::move(comparison));
  }
  return item;
}

int FeaturePipeline::ResolveKey(int key_index, double tau, int frame_index) const {
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

void FeaturePipeline::Retire(int key_index, int frame_index, double tau) {
  const int successor = KeyImageSelector::SuccessorOf(key_index, frame_index);
  std::lock_guard<std::mutex> lock(mutex_);
  retired_[key_index].push_back(Retirement{frame_index, tau, successor});
}

}  // namespace vmap
