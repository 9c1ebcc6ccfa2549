#pragma once
// The heading of one image relative to another: how far the scene both show is shifted horizontally, x in
// the second image minus x in the first, in pixels (and, with a camera, as a bearing in degrees).
//
// A teach-and-repeat robot steers by it, and it must survive appearance change (snow, foliage, low sun),
// where few tentative matches are right and a fundamental matrix rarely holds. So the estimate does not
// rest on F: it is the mode of the horizontal displacements of the tentative matches, the histogram voting
// of the teach-and-repeat literature (Krajnik et al., RAS 2017), taken as the densest window of
// displacements (no bin edges to split a peak) in x and y together, and refined to the median horizontal
// displacement inside it. Wrong matches spread their displacements over the whole image while right ones
// agree, so the window holding the most displacements is the heading even when most matches are wrong. Only
// where F keeps many verified matches (they are then right ones) is their median displacement used. How each
// alternative fared on the michigan seasonal pairs, with ORB and XFeat: docs/seasons.md.

#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/core/option_fields.h"
#include "vmap/geometry/camera.h"

namespace vmap {

struct HeadingOptions {
  // Width of the window of horizontal displacements that votes (pixels, of the images as matched). About
  // the spread of right matches' displacements after a small translation of the camera: wide enough to
  // hold them, narrow against the criterion a heading is judged by (35 px on 1024 px wide images).
  double window_px = 20.0;
  // Height of the window in vertical displacement (pixels; 0 = displacements vote by x alone). A turn shifts
  // the whole scene sideways and a change of pitch or height shifts it up or down by about as much everywhere,
  // so right matches agree in dy too, while wrong ones spread over both: a window in (dx, dy) holds far fewer
  // chance votes than a column of any dy.
  // 40 px: tolerant of the few degrees of pitch between sessions of a robot's camera (michigan's right matches
  // move up or down by more than 25 px in many pairs), still a tenth of a 384-px-high image.
  double window_dy_px = 40.0;
  // The fewest displacements in the winning window for an estimate; below it there is none.
  int min_votes = 3;
  // Where the caller has F-verified matches and F keeps at least this many, the heading is their median
  // displacement instead (0 = always the mode): so many inliers are right matches, and their median is not
  // cut to a window. With XFeat it was right for 1-2 more michigan pairs than the mode (docs/seasons.md),
  // with ORB for as many; it costs nothing where F is estimated anyway (vmap match, vmap localize).
  int min_verified = 50;

  // As a localization run records them (its "options.heading") and their flags (--heading-*).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

enum class HeadingMethod {
  kNone,              // no estimate: too few matches agree
  kDisplacementMode,  // the densest window of the tentative matches' displacements
  kVerifiedMedian,    // the median displacement of the F-verified matches (at least min_verified of them)
};
inline constexpr EnumName<HeadingMethod> kHeadingMethodNames[] = {
    {HeadingMethod::kNone, "none"},
    {HeadingMethod::kDisplacementMode, "displacement_mode"},
    {HeadingMethod::kVerifiedMedian, "verified_median"}};
std::string HeadingMethodName(HeadingMethod method);

struct HeadingEstimate {
  HeadingMethod method = HeadingMethod::kNone;
  // x in the second image minus x in the first at the scene both show; NaN without an estimate.
  double px = std::numeric_limits<double>::quiet_NaN();
  // With a camera: the same as a bearing, the median over the winning matches of atan(x_n) in the second
  // image minus atan(x_n) in the first (x_n undistorted normalised x), in degrees; NaN without.
  double deg = std::numeric_limits<double>::quiet_NaN();
  int votes = 0;       // matches in the winning window (verified_median: the verified matches)
  int num_voters = 0;  // matches that voted (those with finite coordinates)
  // The share of voters in the winning window, votes / num_voters (0 without an estimate). Wrong matches
  // alone put a small share of them into any window (about the window's area over the image's), so a share
  // well above that is a heading many matches agree on.
  double confidence = 0.0;
  bool valid() const { return method != HeadingMethod::kNone; }
};

// The heading from tentative matches points0[i] (first image) <-> points1[i] (second image). `camera`
// (optional) gives `deg`; both images must be in its pixels. Deterministic: ties between windows go to the
// one with the smallest displacements.
HeadingEstimate EstimateHeading(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                const HeadingOptions& options, const Camera* camera = nullptr);

// The same where F was estimated: `verified[i]` != 0 for the matches F keeps (empty when there is no F). With
// at least options.min_verified of them, their median displacement; otherwise the mode of all matches.
HeadingEstimate EstimateHeading(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                const std::vector<unsigned char>& verified, const HeadingOptions& options,
                                const Camera* camera = nullptr);

}  // namespace vmap
