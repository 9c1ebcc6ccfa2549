#include "vmap/mapping/key_image_selector.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/numeric.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

SimilarityMode ParseSimilarityMode(const std::string& name) {
  return ParseEnum(kSimilarityModeNames, name, "similarity");
}

std::string SimilarityModeName(SimilarityMode mode) { return EnumToName(kSimilarityModeNames, mode); }

void KeyImageOptions::Check() const {
  // tau's default is the matcher's (BuildOptions), so its message gives the paper's values instead.
  if (!(tau > 0.0 && tau <= 1.0)) {
    throw OptionError("tau", fmt::format("{} is outside (0, 1]; the paper uses 0.1 to 0.9", tau));
  }
  CheckFieldRanges(*this);
}

PairComparison ComparePair(const Matcher& matcher, const ImageFeatures& features0, const ImageFeatures& features1,
                           const VerifierOptions& verifier, SimilarityMode similarity,
                           const std::vector<double>& decide_taus, const std::function<bool()>& abandon) {
  const TentativeMatches matches = matcher.Match(features0, features1);
  const int denominator = SimilarityDenominator(similarity, static_cast<int>(matches.size()), features0.num_features(),
                                                features1.num_features());
  return VerifyMatches(matches, denominator, verifier, decide_taus, abandon);
}

PairComparison VerifyMatches(const TentativeMatches& matches, int denominator, const VerifierOptions& verifier,
                             const std::vector<double>& decide_taus, const std::function<bool()>& abandon,
                             std::shared_ptr<const MagsacCheckpoint> resume_from) {
  PairComparison result;
  result.num_tentative = static_cast<int>(matches.size());
  // S >= tau  <=>  verified >= the least count v with v / denominator >= tau (in the arithmetic Passes uses).
  EarlyStop early_stop;
  const bool stops_early = verifier.own_magsac && verifier.method == VerifierMethod::kMagsac && !decide_taus.empty();
  if (stops_early) {
    for (double tau : decide_taus) {
      int count = static_cast<int>(std::ceil(tau * denominator));
      while (count > 0 && static_cast<double>(count - 1) / denominator >= tau) --count;
      while (static_cast<double>(count) / denominator < tau) ++count;
      early_stop.min_inliers.push_back(std::max(count, verifier.min_matches));
    }
  }
  early_stop.abandon = abandon;
  early_stop.resume_from = std::move(resume_from);
  const FundamentalResult fundamental =
      EstimateFundamental(matches.points0, matches.points1, verifier, early_stop, &matches.scores);
  if (fundamental.abandoned) {
    result.abandoned = true;
    return result;
  }
  result.correspondences.reserve(matches.size());
  if (fundamental.success) {
    result.matched = true;
    result.F = fundamental.F;
    result.num_verified = fundamental.num_inliers;
    for (size_t i = 0; i < matches.size(); ++i) {
      if (fundamental.inlier_mask[i]) result.correspondences.push_back({matches.points0[i], matches.points1[i]});
    }
  }
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!fundamental.success || !fundamental.inlier_mask[i]) {
      result.correspondences.push_back({matches.points0[i], matches.points1[i]});
    }
  }
  if (result.matched) {
    std::vector<double> displacements;
    displacements.reserve(result.num_verified);
    for (int i = 0; i < result.num_verified; ++i) {
      displacements.push_back(cv::norm(result.correspondences[i].p1 - result.correspondences[i].p0));
    }
    result.median_displacement = Median(std::move(displacements));
    result.similarity = denominator > 0 ? static_cast<double>(result.num_verified) / denominator : 0.0;
  }
  if (stops_early) {
    result.exhaustive = false;
    result.checkpoint = fundamental.checkpoint;
    result.decided_taus = decide_taus;
    std::sort(result.decided_taus.begin(), result.decided_taus.end());
    for (double tau : decide_taus) {
      if (!result.Reaches(tau)) result.lowest_failed_tau = std::min(result.lowest_failed_tau, tau);
    }
  }
  return result;
}

Link MakeLink(const PairComparison& comparison, int from_key, int to_key, bool below_tau) {
  Link link;
  link.from_key = from_key;
  link.to_key = to_key;
  link.below_tau = below_tau;
  link.similarity = comparison.similarity;
  link.num_tentative = comparison.num_tentative;
  link.num_verified = comparison.num_verified;
  link.has_fundamental = comparison.matched;
  link.F = comparison.F;
  link.correspondences = comparison.correspondences;
  return link;
}

KeyImageSelector::KeyImageSelector(KeyImageOptions options, KeyImageFn on_key_image, EvaluationFn on_evaluation,
                                   LinkFn on_link)
    : options_(options),
      on_key_image_(std::move(on_key_image)),
      on_evaluation_(std::move(on_evaluation)),
      on_link_(std::move(on_link)) {
  options_.Check();
}

bool KeyImageSelector::ShowsKeyView(const PairComparison& comparison) const {
  // A displacement < 0 was not measured (a comparison made elsewhere): the frame counts as a new view.
  return comparison.matched && comparison.median_displacement >= 0.0 &&
         comparison.median_displacement < options_.min_key_displacement;
}

void KeyImageSelector::AddKeyImage(const FrameRecord& record, const std::string& reason) {
  KeyImage key;
  key.frame_index = record.frame->index;
  key.source_index = record.frame->source_index;
  key.timestamp = record.frame->timestamp;
  key.source_name = record.frame->source_name;
  key.num_features = record.features->num_features();
  key.reason = reason;
  if (on_key_image_) on_key_image_(record, key);
  spdlog::debug("tau {:.2f}: key image {} = frame {} ({})", options_.tau, key_images_.size(), key.frame_index, reason);
  key_images_.push_back(std::move(key));
  key_ = record;
  previous_.reset();
  still_frames_ = 0;
  last_frame_still_ = false;
}

void KeyImageSelector::AddLink(const PairComparison& comparison, bool below_tau) {
  const int to_key = static_cast<int>(key_images_.size()) - 1;
  links_.push_back(MakeLink(comparison, to_key - 1, to_key, below_tau));
  if (on_link_) on_link_(links_.back(), comparison);
}

void KeyImageSelector::Add(const FrameRecord& record, const CompareFn& compare) {
  if (finished_) throw std::logic_error("KeyImageSelector::Add after Finish");
  ++num_frames_;
  if (!key_) {
    AddKeyImage(record, "first frame");
    return;
  }
  // Compare the frame with the key image; on failure the previous frame becomes the key image and the
  // frame is compared again with it, so no frame is skipped.
  for (;;) {
    PairComparison comparison = compare(*key_, record);
    const Evaluation evaluation{key_->frame->index,       record.frame->index,     comparison.similarity,
                                comparison.num_tentative, comparison.num_verified, comparison.matched};
    if (on_evaluation_) {
      on_evaluation_(evaluation);
    } else {
      evaluations_.push_back(evaluation);
    }
    if (comparison.Reaches(options_.tau)) {
      last_frame_still_ = ShowsKeyView(comparison);
      if (last_frame_still_) {
        ++still_frames_;  // the key image's view again: not a candidate for the next key image
        return;
      }
      previous_ = record;
      previous_comparison_ = std::move(comparison);
      return;
    }
    const std::string why = comparison.matched
                                ? fmt::format("S(frame {}, frame {}) = {:.3f} < tau", key_->frame->index,
                                              record.frame->index, comparison.similarity)
                                : fmt::format("matching frame {} with key frame {} failed ({} tentative matches)",
                                              record.frame->index, key_->frame->index, comparison.num_tentative);
    if (!previous_) {
      // No frame since the key image passed with a view of its own: the very next frame fails, or those
      // before it repeat the key image's view. The failing frame becomes a key image, linked below tau.
      const std::string what = still_frames_ == 0
                                   ? "; the next frame already fails: linked below tau"
                                   : fmt::format(
                                         "; the {} frame(s) before it repeat the key image's view: linked "
                                         "below tau",
                                         still_frames_);
      AddKeyImage(record, why + what);
      AddLink(comparison, /*below_tau=*/true);
      return;
    }
    const FrameRecord promoted = *previous_;
    PairComparison promoted_comparison = std::move(previous_comparison_);
    AddKeyImage(promoted, why);
    AddLink(promoted_comparison, /*below_tau=*/false);
  }
}

void KeyImageSelector::Finish() {
  if (finished_) return;
  finished_ = true;
  // When the last frame shows the key image's view again, the key image already is the route's goal.
  if (options_.final_key && previous_ && !last_frame_still_) {
    const FrameRecord last = *previous_;
    PairComparison comparison = std::move(previous_comparison_);
    AddKeyImage(last, "final frame");
    AddLink(comparison, /*below_tau=*/false);
  }
  key_.reset();
  previous_.reset();
}

void KeyImageOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"tau"}, tau);
  visitor.Visit({"similarity", "--similarity",
                 "S = verified / tentative matches (inlier-ratio) or / features detected (feature-ratio)"},
                EnumField(similarity, kSimilarityModeNames, ParseSimilarityMode));
  visitor.Visit({"final_key", "!--no-final-key", "Do not make the last frame a key image"}, final_key);
  visitor.Visit(
      OptionField{"min_key_displacement", "--min-key-displacement",
                  "Pixels: a frame whose matches with the key image moved less (median) repeats its view and is "
                  "never made a key image; 0 = off (Algorithm 1 as published)"}
          .Within(0, 100)
          .Unit("px")
          .Meaning("0 turns the check off"),
      min_key_displacement);
}

}  // namespace vmap
