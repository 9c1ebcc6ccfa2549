#pragma once
// Geometric verification of tentative matches with a fundamental matrix (OpenCV RANSAC / USAC).

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/core/option_fields.h"
#include "vmap/geometry/sampson_error.h"  // SampsonDistance: how far a match is from F

namespace vmap {

struct MagsacCheckpoint;  // magsac.cc

enum class VerifierMethod { kMagsac, kRansac, kUsac, kAccurate };
// USAC_MAGSAC, FM_RANSAC, USAC_DEFAULT, USAC_ACCURATE.
inline constexpr EnumName<VerifierMethod> kVerifierMethodNames[] = {{VerifierMethod::kMagsac, "magsac"},
                                                                    {VerifierMethod::kRansac, "ransac"},
                                                                    {VerifierMethod::kUsac, "usac"},
                                                                    {VerifierMethod::kAccurate, "accurate"}};
VerifierMethod ParseVerifierMethod(const std::string& name);
std::string VerifierMethodName(VerifierMethod method);

struct VerifierOptions {
  // Defaults follow Kornia's LoFTR + MAGSAC tutorial, which the paper's code most likely followed.
  VerifierMethod method = VerifierMethod::kMagsac;
  double threshold = 0.5;  // pixels (epipolar distance for RANSAC, MAGSAC's sigma bound)
  double confidence = 0.999;
  int max_iterations = 100000;
  int seed = 0;         // the random generator's state: the same input gives the same inliers
  int min_matches = 8;  // fewer tentative matches than this means matching failed
  // kMagsac only: false runs OpenCV's USAC_MAGSAC (the paper's exact behaviour); true runs vmap's own MAGSAC++
  // (magsac.h), which agrees with it within the noise of a seed change and can stop early (EarlyStop).
  bool own_magsac = false;
  // Own MAGSAC++ stopping early only: "fewer inliers than the target" is settled after at most this many
  // samples, where the confidence criterion for the target's inlier ratio would draw more (31,600 at 0.3, the
  // 100,000 cap at 0.25 and below). The criterion counts only all-inlier samples; local optimisation also recovers the
  // model from samples with an outlier or two, so far fewer samples find it. On rccar_room's sweep 10,000 cut
  // the CPU and flipped about as many of the exhaustive run's decisions as a change of seed does
  // (docs/measurements/code-choices.md, "Stopping verification once the decisions are settled").
  // max_iterations keeps the confidence criterion alone.
  int max_samples_to_reject = 10000;
  // Bounded verification of scored matches (kMagsac, no EarlyStop targets, one score per match), whatever
  // own_magsac says: with N > 0, vmap's MAGSAC++ draws at most max_samples_to_reject samples from the N
  // best-scored matches and refines the model found on all of them (EstimateFundamentalMagsacOnBest), so that
  // thousands of matches cost what N do. Matches without scores (ORB) get the verifier above. 0 (default): off.
  // Not recorded in map.json: maps are built without it; localization uses it (MapVerifierOptions).
  int loop_points = 0;

  // The verifier as map.json records it and its flags: method, threshold, confidence, max_iterations, seed,
  // min_matches, max_samples_to_reject (not own_magsac: MapBuilderOptions::exhaustive records which estimator
  // decided).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct FundamentalResult {
  bool success = false;  // a model was found from at least min_matches tentative matches
  cv::Matx33d F = cv::Matx33d::zeros();
  std::vector<unsigned char> inlier_mask;  // one per tentative match; empty when !success
  int num_inliers = 0;
  bool abandoned = false;  // EarlyStop::abandon ended it: not a result, discard it
  // Set when vmap's MAGSAC++ stopped early (EarlyStop): where its sample loop stopped. Given back as
  // EarlyStop::resume_from with the same correspondences and options, the estimation goes on from there.
  std::shared_ptr<const MagsacCheckpoint> checkpoint;
};

// What a caller will decide from the result: for each entry t, "at least t inliers?". Empty: estimate
// exhaustively. Only vmap's own MAGSAC++ stops early (see magsac.h); OpenCV's estimators ignore it.
struct EarlyStop {
  std::vector<int> min_inliers;
  // Polled now and then; when it returns true the estimation stops with `abandoned` set (the answer is no
  // longer needed, e.g. the key image was replaced meanwhile).
  std::function<bool()> abandon;
  // Continues the run that left this checkpoint (FundamentalResult::checkpoint) instead of starting over; the
  // same correspondences (in any order) and options are required. With no targets the result is exactly that
  // of an exhaustive run from the start, which costs only the samples the first run had not drawn.
  std::shared_ptr<const MagsacCheckpoint> resume_from;
};

// `scores`: one per match, higher is better (TentativeMatches::scores), read only for options.loop_points.
FundamentalResult EstimateFundamental(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                      const VerifierOptions& options, const EarlyStop& early_stop = {},
                                      const std::vector<float>* scores = nullptr);

}  // namespace vmap
