#include "vmap/mapping/key_image_search.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "vmap/core/progress.h"
#include "vmap/core/stopwatch.h"
#include "vmap/map/map_writer.h"
#include "vmap/mapping/collect_map.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/mapping/link_verifier.h"

namespace vmap {

VisualMap SearchKeyImages(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                          const std::filesystem::path& directory, const std::string& options_json) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const VerifierOptions verifier = DecisionVerifier(options);
  const std::vector<double> taus =
      verifier.own_magsac ? std::vector<double>{options.key_images.tau} : std::vector<double>{};
  // Frames compared with the key per round, each on a thread of its own. Fixed, not the number of threads: which
  // frames are probed decides which key images are found where S does not fall monotonically, and the map must be
  // the same whatever --threads is (it was not: 6 key images with one thread, 7 with two, on lab_floor's 300 frames).
  // Two is what this project's 2-core machine ran before, so its bisect maps are unchanged.
  constexpr int kProbes = 2;
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
    if (!record.features) record.features = matcher.ExtractFrame(record.frame->gray, record.frame->color);
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
        if (!frame.features) frame.features = matcher.ExtractFrame(frame.frame->gray, frame.frame->color);
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
      if (!c.Reaches(options.key_images.tau)) return position;
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
  KeyImageSelector selector(options.key_images, on_key_image);
  // The selector's comparisons: those the search made, or made now.
  const KeyImageSelector::CompareFn compare_cached = [&](const FrameRecord& key, const FrameRecord& frame) {
    const auto it = comparisons.find({key.frame->index, frame.frame->index});
    if (it != comparisons.end()) return it->second;
    return remember(key.frame->index, frame.frame->index, compare(key, frame));
  };
  std::unique_ptr<LinkVerifier> link_verifier;
  if (verifier.own_magsac) link_verifier = std::make_unique<LinkVerifier>(VerifierOptions(verifier));

  if (read_until(0) == 0) {
    selector.Add(with_features(0), compare_cached);
    int last_pass = 0, fed = 0, step = 1;
    for (;;) {
      const FrameRecord key = *selector.current_key();
      frames.erase(frames.begin(), frames.lower_bound(last_pass));  // the selector holds the key itself
      // Gallop: offsets step .. 2^(kProbes - 1) step, at most `window` ahead.
      int first_fail = -1;
      while (first_fail < 0 && read_until(last_pass + 1) > last_pass) {
        const int reach = std::min(window, step << std::min(kProbes - 1, 20));
        std::vector<int> positions;
        for (int i = 1; i <= kProbes; ++i) {
          const int position = read_until(last_pass + std::max(1, reach * i / kProbes));
          if (positions.empty() || position > positions.back()) positions.push_back(position);
        }
        first_fail = probe(key, positions, &last_pass);
        step = std::min(window, 2 * reach);
      }
      if (first_fail < 0) {  // the last frame passes: it is the final key image (Finish)
        if (last_pass > fed) selector.Add(frames.at(last_pass), compare_cached);
        break;
      }
      // Bisect: the frames between the last passing and the first failing frame, split into kProbes + 1 parts.
      while (first_fail - last_pass > 1) {
        std::vector<int> positions;
        for (int i = 1; i <= kProbes; ++i) {
          const int position = last_pass + (first_fail - last_pass) * i / (kProbes + 1);
          if (position > last_pass && position < first_fail && (positions.empty() || position > positions.back())) {
            positions.push_back(position);
          }
        }
        if (positions.empty()) positions.push_back(last_pass + 1);
        const int failing = probe(key, positions, &last_pass);
        if (failing >= 0) first_fail = failing;
      }
      // Algorithm 1 on the frames found: the last passing frame, then the first failing one.
      if (last_pass > fed) selector.Add(frames.at(last_pass), compare_cached);
      selector.Add(with_features(first_fail), compare_cached);
      fed = last_pass = first_fail;
      step = 1;
    }
  }
  progress.Finish();
  if (selector.key_images().empty()) ThrowNoFrameUsed(source);
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
  const double seconds = SecondsSince(start);
  VisualMap map = CollectMap(selector, source, matcher, options, options_json, seconds, /*analyze_links=*/true,
                             link_verifier.get(), options.key_images.tau, /*analysis_cache=*/nullptr, writer.get());
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

}  // namespace vmap
