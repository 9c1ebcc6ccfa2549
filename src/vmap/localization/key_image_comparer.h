#pragma once
// How the Localizer compares a frame with one key image: matched by the map's matcher, verified like the map's links
// (the fundamental-matrix verifier), accepted by the acceptance rule (acceptance.h), its heading estimated from every
// tentative match; and, for the comparison that guides the robot, the relative pose. One definition for every rule
// of the localizer, and for frames compared ahead on other threads: every method is const and thread-safe.

#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/features/matcher.h"
#include "vmap/localization/key_comparison.h"
#include "vmap/localization/key_image_store.h"
#include "vmap/localization/localizer_options.h"

namespace vmap {

class KeyImageComparer {
 public:
  // `keys` and `matcher` must outlive the comparer. Until SetShareReference, the link share asks for nothing.
  KeyImageComparer(const KeyImageStore& keys, const Matcher& matcher, LocalizerOptions options);

  // The frame's features against key image `key` (its best view where the map has experiences), the verifier's
  // iterations at most `max_iterations` where above 0.
  KeyComparison Compare(const ImageFeatures& features, int key, int max_iterations = 0) const;
  // The frame against one image of key image `key` (the key image itself or a view), from their matches.
  KeyComparison CompareImage(const ImageFeatures& features, const ImageFeatures& image, const TentativeMatches& matches,
                             int key, int max_iterations = 0) const;
  // Matching guided by the prediction (LocalizerOptions::window_matching): the frame (`window_features`: the window
  // matcher's features of it, or the frame's own; `size`, its size) against key image `key`, matched only within the
  // window around `predicted_dx`, the previous frame's heading against it; accepted by window_max_log10_nfa.
  KeyComparison CompareInWindow(const ImageFeatures& window_features, int key, double predicted_dx,
                                cv::Size size) const;
  // Adds the relative pose, its translation sigma and whether the translation is known to a comparison of the teach
  // key image (experience 0) that matched, when the options have a camera.
  void AddPose(KeyComparison& comparison) const;

  // What the acceptance's link share measures each key image's comparisons against (verified matches, per key image;
  // Localizer: the map's links, or on a map denser than LocalizerOptions::link_share_tau the links a map of that tau
  // would hold).
  void SetShareReference(std::vector<int> share_reference) { share_reference_ = std::move(share_reference); }
  // The verified matches a comparison with key image `key` needs by the link share (min_link_share).
  double LinkShareBar(int key) const {
    return share_reference_.empty() ? 0.0 : options_.min_link_share * share_reference_[key];
  }

 private:
  const KeyImageStore& keys_;
  const Matcher& matcher_;
  const LocalizerOptions options_;
  std::vector<int> share_reference_;  // per key image; empty: none yet
};

}  // namespace vmap
