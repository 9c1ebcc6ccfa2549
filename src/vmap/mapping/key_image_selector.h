#pragma once
// The key-image selection of García-Pintos et al. (2023), Algorithm 1, one frame at a time, so that a
// sequence of any length streams through it and a threshold sweep runs every tau in one pass.

#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/core/option_fields.h"
#include "vmap/features/matcher.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/map/visual_map.h"

namespace vmap {

enum class SimilarityMode {
  kInlierRatio,   // |D| = tentative matches: S = verified / tentative (reproduces the paper's tables)
  kFeatureRatio,  // |D| = features detected: S = verified / max(|D_i|, |D_j|) (the paper's literal text)
};
inline constexpr EnumName<SimilarityMode> kSimilarityModeNames[] = {{SimilarityMode::kInlierRatio, "inlier-ratio"},
                                                                    {SimilarityMode::kFeatureRatio, "feature-ratio"}};
SimilarityMode ParseSimilarityMode(const std::string& name);
std::string SimilarityModeName(SimilarityMode mode);

// |D| of S = verified / |D| under `mode`, the one place it is written (selector, link verifier, localizer): the
// tentative matches of the pair, or the larger of the two images' feature counts.
inline int SimilarityDenominator(SimilarityMode mode, int num_tentative, int num_features0, int num_features1) {
  return mode == SimilarityMode::kInlierRatio ? num_tentative : std::max(num_features0, num_features1);
}

struct KeyImageOptions {
  double tau = 0.5;  // similarity threshold in (0, 1]
  SimilarityMode similarity = SimilarityMode::kInlierRatio;
  bool final_key = true;  // the last frame becomes the final key image (the route's goal)
  // Pixels. A frame whose verified matches with the key image moved less than this (median) shows the key
  // image's view again: a repeated frame (7-Scenes repeats a frame when one was dropped) or a camera at
  // rest. Such a frame passes the test (S is near 1) but is never promoted to key image: a link between two
  // views of one viewpoint has no parallax and a meaningless F. 0 turns this off (Algorithm 1 as published).
  double min_key_displacement = 1.0;

  // Algorithm 1's options as map.json records them: tau, similarity, final_key, min_key_displacement. tau has
  // no flag here: its default depends on the matcher (pipelines/build_pipeline.h has the option, --tau).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// One processed frame with its features, as the selector sees it.
struct FrameRecord {
  std::shared_ptr<const Frame> frame;
  std::shared_ptr<const ImageFeatures> features;
};

// The outcome of comparing a key image with a frame: S and everything a link keeps.
struct PairComparison {
  bool matched = false;  // enough tentative matches and a fundamental matrix
  double similarity = 0.0;
  int num_tentative = 0;
  int num_verified = 0;
  cv::Matx33d F = cv::Matx33d::zeros();
  std::vector<Correspondence> correspondences;  // verified first, then rejected
  double median_displacement = -1.0;            // pixels, over the verified matches; -1 when not matched
  // False when verification stopped as soon as S >= tau was settled for the thresholds asked (ComparePair's
  // `decide_taus`): S is then the best found by that point, and only Decides(tau) says whether it answers tau.
  bool exhaustive = true;
  double lowest_failed_tau = 2.0;  // when not exhaustive: the lowest tau asked that S did not reach
  // When not exhaustive: the thresholds verification was asked to settle, ascending. Where it stopped, and so
  // S, depends on all of them, not only on the one a caller wants answered.
  std::vector<double> decided_taus;
  bool abandoned = false;  // `abandon` stopped the verification: this answers nothing
  // When not exhaustive: where verification stopped. VerifyMatches given it back (`resume_from`) goes on from
  // there instead of starting over, e.g. to verify a link in full.
  std::shared_ptr<const MagsacCheckpoint> checkpoint;
  // Algorithm 1's test, the one place it is written: the frame passes against the key image at threshold tau.
  bool Reaches(double tau) const { return matched && similarity >= tau; }
  bool Decides(double tau) const { return exhaustive || Reaches(tau) || tau >= lowest_failed_tau; }
};

// Matches two images and verifies the matches: the S(I_i, I_j) of the paper. With `decide_taus` and a verifier
// that can stop early (VerifierOptions::own_magsac), verification stops once "S >= tau?" is settled for each of
// them; without, it runs to the verifier's confidence criterion. `abandon` (same verifier only) is polled during
// verification and stops it when the answer is no longer needed.
PairComparison ComparePair(const Matcher& matcher, const ImageFeatures& features0, const ImageFeatures& features1,
                           const VerifierOptions& verifier, SimilarityMode similarity,
                           const std::vector<double>& decide_taus = {}, const std::function<bool()>& abandon = nullptr);

// The verification half of ComparePair, on matches already made: S = verified / `denominator` (|D|).
// `resume_from`, a checkpoint of an earlier verification of these matches that stopped early, continues that
// run: without `decide_taus` the result is the full verification's, for the samples not drawn yet.
PairComparison VerifyMatches(const TentativeMatches& matches, int denominator, const VerifierOptions& verifier,
                             const std::vector<double>& decide_taus = {},
                             const std::function<bool()>& abandon = nullptr,
                             std::shared_ptr<const MagsacCheckpoint> resume_from = nullptr);

// The link between key images from_key and to_key that `comparison` verified.
Link MakeLink(const PairComparison& comparison, int from_key, int to_key, bool below_tau);

class KeyImageSelector {
 public:
  using CompareFn = std::function<PairComparison(const FrameRecord& key, const FrameRecord& frame)>;
  // Called once for every new key image, e.g. to write its image file (may set image_file).
  using KeyImageFn = std::function<void(const FrameRecord& record, KeyImage& key)>;

  // Called with every comparison made (what map.json's evaluations hold). When given, the selector does not
  // keep them (evaluations() stays empty), so that its memory does not grow with the sequence's length.
  using EvaluationFn = std::function<void(const Evaluation& evaluation)>;
  // Called once for every new link (already in links()), with the comparison it was made from.
  using LinkFn = std::function<void(const Link& link, const PairComparison& comparison)>;

  explicit KeyImageSelector(KeyImageOptions options, KeyImageFn on_key_image = nullptr,
                            EvaluationFn on_evaluation = nullptr, LinkFn on_link = nullptr);

  // Algorithm 1's successor rule, for those who compare ahead of the selector (MapBuilder's workers): when
  // frame `failing_frame` falls below tau against the key image at `key_frame`, the next key image is the frame
  // before it, or the failing frame itself when that is the key (a link below tau). The selector itself may
  // pick an earlier frame when the last ones repeat the key image's view (min_key_displacement): a guess
  // then, which the selector's own comparisons correct.
  static int SuccessorOf(int key_frame, int failing_frame) {
    return failing_frame - 1 == key_frame ? failing_frame : failing_frame - 1;
  }

  // Frames must arrive in order. The first frame becomes the first key image. `compare` gives the comparisons
  // this frame needs (with the key image, and with a new key image when it falls below tau): the caller's, per
  // frame, e.g. from comparisons made ahead for it.
  void Add(const FrameRecord& record, const CompareFn& compare);
  // Ends the sequence: adds the final key image when asked to.
  void Finish();

  const std::vector<KeyImage>& key_images() const { return key_images_; }
  const std::vector<Link>& links() const { return links_; }
  const std::vector<Evaluation>& evaluations() const { return evaluations_; }
  int num_frames() const { return num_frames_; }
  // The current key image, or null before the first frame and after Finish.
  const FrameRecord* current_key() const { return key_ ? &*key_ : nullptr; }

 private:
  bool ShowsKeyView(const PairComparison& comparison) const;
  void AddKeyImage(const FrameRecord& record, const std::string& reason);
  void AddLink(const PairComparison& comparison, bool below_tau);

  KeyImageOptions options_;
  KeyImageFn on_key_image_;
  EvaluationFn on_evaluation_;
  LinkFn on_link_;
  std::optional<FrameRecord> key_;
  std::optional<FrameRecord> previous_;  // the last frame that passed against the key image
  PairComparison previous_comparison_;   // key vs previous_
  int still_frames_ = 0;                 // frames since the key image that showed its view again
  bool last_frame_still_ = false;        // the last frame added showed the key image's view again
  std::vector<KeyImage> key_images_;
  std::vector<Link> links_;
  std::vector<Evaluation> evaluations_;
  int num_frames_ = 0;
  bool finished_ = false;
};

}  // namespace vmap
