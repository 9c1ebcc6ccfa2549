#pragma once
// The frame compared with one key image (Localizer::Compare), and which of two comparisons is the better match.

#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/geometry/heading.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/map/visual_map.h"

namespace vmap {

// The frame compared with one key image.
struct KeyComparison {
  int key = -1;             // key-image index in the map; -1: not compared
  bool matched = false;     // matching and verification succeeded
  bool accepted = false;    // matched, and the acceptance rule holds (LocalizerOptions::acceptance)
  double similarity = 0.0;  // S
  int num_tentative = 0;
  int num_verified = 0;
  cv::Matx33d F = cv::Matx33d::zeros();  // x_key^T F x_frame = 0 (pixels); zero when !matched
  // The heading of the frame against the key image, x in the frame minus x in the key image (px; with a camera
  // also degrees), from all tentative matches (geometry/heading.h): it holds across seasons, where F rarely does.
  HeadingEstimate heading;
  // The verified matches, p0 in the frame and p1 in the compared image (pixels); empty when !matched.
  std::vector<Correspondence> verified;
  // With a camera, on the target comparison of a result (LocalizationResult::to_next, or to_key at the route's
  // end): the key image's camera relative to the frame's, X_key = R X_frame + t, t of unit length
  // (PoseFromFundamental on F and the verified matches, refined by RefineRelativePose and decided again by
  // EnforceCheirality, so t never points backwards). Invalid without a camera, and on the other comparisons:
  // a pose costs as much as a verification, and only the target's guides the robot (Localizer::AddPose).
  RelativePose pose;
  // How well the verified matches determine the pose's translation direction (TranslationSigmaDeg, degrees;
  // NaN without a pose) and whether it is trusted (TranslationKnown with LocalizerOptions::translation).
  double translation_sigma_deg = std::numeric_limits<double>::quiet_NaN();
  bool translation_known = false;
  // log10 of the number of false alarms of the verified set (ChanceOfComparison): how often chance alone
  // would explain it over all the comparisons one frame can make. +infinity when !matched.
  double log10_nfa = std::numeric_limits<double>::infinity();
  // Which image of the key was compared, the best fitting: 0 the teach run's key image, n > 0 the view of
  // experience n (map/experiences.h). With a view, the counts, S, F and log10_nfa are the frame's against the
  // view; the heading is against the key image (the view's heading plus the view's own against the key image);
  // there is no pose (the view's pose to the key image is not known).
  int experience = 0;
};

// Which of two comparisons is the better match: `a` is accepted and `b` is not, or both are and `a` has more
// verified matches (then higher S). The measure was chosen on the bracket test (docs/measurements/code-choices.md,
// "The better of two key images").
bool IsBetterMatch(const KeyComparison& a, const KeyComparison& b);
// Which of two images of one key image (the key image, a view) fits a frame better: IsBetterMatch, and when
// neither is accepted, more verified matches (the heading is still reported), then higher S. Ties keep `b`.
bool FitsBetter(const KeyComparison& a, const KeyComparison& b);
// Accepted, and its verified set at a log10 NFA of at most `max_log10_nfa`: beyond that much chance (a bar stricter
// than the acceptance rule's, such as Localizer::kBeyondLittleChance).
bool PassesChance(const KeyComparison& comparison, double max_log10_nfa);

}  // namespace vmap
