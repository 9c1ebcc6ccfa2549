#pragma once
// vmap's own MAGSAC++ for the fundamental matrix, whose loop can stop as soon as the caller's decisions are
// settled.
//
// Why not OpenCV's USAC_MAGSAC: key-image selection only asks whether S >= tau, and a sweep asks that for a
// handful of tau. Once the best model found reaches a tau, that answer is known; once enough samples were drawn
// to find a model reaching tau if there were one (ln(1 - confidence) / ln(1 - w^7) for the inlier ratio w that
// tau needs), the answer "no" is known with the requested confidence. OpenCV's loop cannot be stopped there: it
// runs until the confidence criterion of the best model it found, which for pairs below tau = 0.3 is the
// 100,000-iteration cap. Stopping at the settled decisions makes a sweep's estimation several times cheaper
// (docs/measurements/code-choices.md, "Stopping verification once the decisions are settled").
//
// Run without targets it estimates exhaustively, as USAC_MAGSAC does (OpenCV 4.6, calib3d/src/usac): uniform
// 7-point samples; models breaking the oriented epipolar constraint are dropped; SPRT (Matas & Chum 2008)
// rejects bad models after a few points; models are ranked by the MAGSAC++ score (Barath et al., CVPR 2020;
// 4 degrees of freedom, sigma_max = 2.5 px / 3.64) of their squared Sampson errors; sigma-consensus++
// (iteratively re-weighted least squares with MAGSAC++ weights on at most 50 points, 10 rounds) refines every
// tenth sample's models and, after 100 iterations, each new best model; a new best model whose sample has five
// points on one plane is replaced by a plane-and-parallax model (DEGENSAC, Chum et al., CVPR 2005); at the end
// up to three least-squares fits on the inliers polish the best model; the inliers are the points whose Sampson
// distance is below the threshold. It matches OpenCV's results within the noise of OpenCV's own seed (see
// magsac_test.cc and bench/estimator_compare.cc), not bit for bit: the random streams differ.
//
// The code, for a reader: robust_loop.h is the loop (sampling, SPRT, the stop, the state a stopped loop resumes
// from), apart from any model; fundamental_solvers.h the 7-point and 8-point solvers; magsac_scoring.h the
// MAGSAC++ score and sigma-consensus++; degensac.h the plane-and-parallax recovery; magsac.cc puts them
// together (the loop's Problem), resumes, polishes and reports.

#include <vector>

#include <opencv2/core.hpp>

#include "vmap/geometry/fundamental.h"

namespace vmap {

struct MagsacStatistics {
  int iterations = 0;     // samples drawn
  int models_scored = 0;  // models evaluated (SPRT-rejected ones included)
  int local_optimizations = 0;
  bool stopped_early = false;  // every decision was settled before the confidence criterion
};

// Estimates F (x1^T F x0 = 0) with the options' threshold, confidence, max_iterations, seed and min_matches
// (options.method is not read). With `early_stop`, the loop ends as soon as, for every target t, either a model
// with at least t inliers was found or min(SamplesToSettle(t / n, ...), options.max_samples_to_reject) samples
// were drawn; the run without targets goes on from there with the same samples. Deterministic: the same
// correspondences (in any order) and seed give the same result.
FundamentalResult EstimateFundamentalMagsac(const std::vector<cv::Point2f>& points0,
                                            const std::vector<cv::Point2f>& points1, const VerifierOptions& options,
                                            const EarlyStop& early_stop = {}, MagsacStatistics* statistics = nullptr);

// The same estimation (without targets) at a cost that does not grow with the matches: when there are more than
// options.loop_points matches and a score for each (TentativeMatches::scores, higher is better), the sample loop
// runs on the loop_points best-scored ones only (PROSAC's ordering: a matcher's most confident matches are the
// likeliest inliers), and its model is then refined by sigma-consensus++ and least squares on every match, whose
// inliers it reports. Otherwise (loop_points 0, fewer matches, no scores) it is EstimateFundamentalMagsac.
// Deterministic as that is: the subset is chosen by score, ties by coordinates.
FundamentalResult EstimateFundamentalMagsacOnBest(const std::vector<cv::Point2f>& points0,
                                                  const std::vector<cv::Point2f>& points1,
                                                  const std::vector<float>& scores, const VerifierOptions& options,
                                                  MagsacStatistics* statistics = nullptr);

// Samples of 7 that must be drawn to find, with the given confidence, an all-inlier sample when a share
// `inlier_ratio` of the points are inliers: ceil(ln(1 - confidence) / ln(1 - inlier_ratio^7)), at most
// max_iterations (also when the ratio is 0).
int SamplesToSettle(double inlier_ratio, double confidence, int max_iterations);

}  // namespace vmap
