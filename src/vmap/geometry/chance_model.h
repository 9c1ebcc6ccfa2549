#pragma once
// How likely a set of matches verified by a fundamental matrix is to have arisen by chance: the number of
// false alarms (NFA) of the a-contrario model of Moisan and Stival (2004), as AC-RANSAC / ORSA score a model.
//
// Null hypothesis: the two images show unrelated scenes, so the point of a tentative match in one image is
// independent of its point in the other, and uniform over that image. A given epipolar line then passes
// within e pixels of a random point with probability at most alpha(e) = 2 e D / A (a strip of width 2e and at
// most the diagonal D long, over the area A). F has 7 degrees of freedom: a model drawn from 7 of n matches
// (3 models per 7-point sample) fits those 7 by construction, and each of the other matches lies within e of
// its line with probability alpha(e). The expected number of models, over every sample, every count k and
// every one of `num_hypotheses` places tried, that explain k matches within e by chance is at most
//
//   NFA(k, e) = num_hypotheses * 3 (n - 7) * C(n, k) * C(k, 7) * alpha(e)^(k - 7)
//
// (the union bound; ORSA's formula). A verified set with NFA < 1 (log10 NFA < 0) is one that chance explains
// less than once over all the tests made: the matches see one scene. docs/localization-acceptance.md derives it
// and measures it on the data.

#include <limits>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

// The probability that a point uniform over an image of `size` lies within `distance` pixels of a given line:
// at most 2 * distance * diagonal / area, capped at 1.
double RandomInlierProbability(double distance, cv::Size size);

// log10 NFA(k, e) above for `num_matches` (n) tentative matches of which `num_inliers` (k) lie within e of
// their epipolar lines, alpha = RandomInlierProbability(e). +infinity for k < 8 (no F is verified by fewer);
// -infinity when alpha is 0 (matches exactly on their lines, k > 7).
// For fixed n and alpha it decreases with k once k exceeds the count chance alone would put within e,
// 7 + alpha (n - 7); it increases with n, alpha and num_hypotheses.
double Log10FalseAlarms(int num_matches, int num_inliers, double alpha, double num_hypotheses = 1.0);

// The distance of a match from F's epipolar geometry: the larger of the two point-to-epipolar-line distances
// (x1^T F x0 = 0; the line F x0 in image 1 and F^T x1 in image 0), in pixels. Infinity when a line is undefined.
double EpipolarDistance(const cv::Matx33d& F, const cv::Point2f& p0, const cv::Point2f& p1);

struct ChanceOfMatches {
  double log10_nfa = std::numeric_limits<double>::infinity();  // the least over k; +inf: fewer than 8 matches
  int num_inliers = 0;   // the k that gives it: matches within threshold of their epipolar lines
  double threshold = 0;  // pixels: the EpipolarDistance of the k-th nearest match
};

// The a-contrario score of F on all of a pair's tentative matches (points0[i] in the image of `size0`,
// points1[i] in that of `size1`, x1^T F x0 = 0): the matches sorted by EpipolarDistance, and the least
// log10 NFA over k of the k nearest (AC-RANSAC's choice of threshold: no fixed inlier threshold is assumed).
// alpha(e) is the smaller of the two images' (the nearer match is within e in both). Distances under 1e-4 px
// (float rounding) count as 1e-4 px.
ChanceOfMatches ChanceOfFundamental(const cv::Matx33d& F, const std::vector<cv::Point2f>& points0,
                                    const std::vector<cv::Point2f>& points1, cv::Size size0, cv::Size size1,
                                    double num_hypotheses = 1.0);

}  // namespace vmap
