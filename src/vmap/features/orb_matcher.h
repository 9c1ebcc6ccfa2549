#pragma once
// ORB (OpenCV) with brute-force Hamming matching, the paper's classical matcher.

#include <memory>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher.h"

namespace vmap {

struct OrbMatcherOptions {
  static constexpr const char* kModelName = "orb";  // --matcher orb (features/matcher_registry.h)
  // Defaults are OpenCV's ORB defaults, which the paper's prototype most likely used.
  int num_features = 500;
  double scale_factor = 1.2;
  int num_levels = 8;
  int edge_threshold = 31;
  int fast_threshold = 20;
  // 0: OpenCV's detector (the fields above). N > 0: FAST per N px grid cell at every pyramid level, features
  // spread over the cells and the levels (features/orb_extraction.h); edge_threshold is then the border at every
  // level in that level's pixels. Absent from a map's JSON: 0, the extraction the map was built with.
  int grid_cell = 0;
  // Grid only: FAST's threshold in the cells where fast_threshold finds no corner.
  int min_fast_threshold = 7;
  // Contrast-limited histogram equalisation (cv::createCLAHE, 8 x 8 tiles) before extraction: its clip limit;
  // 0 = none. Absent from a map's JSON: 0.
  double clahe_clip = 0.0;
  // Keep a match only if it is the best in both directions (BFMatcher's crossCheck).
  bool cross_check = true;
  // Lowe's ratio test on Hamming distances: keep if best < ratio * second best. 0 disables it.
  double ratio = 0.0;

  void Check() const;                             // throws OptionError naming the bad field
  void VisitFields(OptionFieldVisitor& visitor);  // JSON keys and command-line flags
};

std::unique_ptr<Matcher> CreateOrbMatcher(const OrbMatcherOptions& options);

// Brute-force Hamming matching of binary descriptors (CV_8U rows, any width that is a multiple of 8 bytes).
// AVX2 for 256-bit descriptors, POPCNT otherwise: the same matches as cv::BFMatcher(NORM_HAMMING, crossCheck), many
// times faster (docs/measurements/code-choices.md, "ORB matching with AVX2").
// Returns pairs (query row, train row).
std::vector<std::pair<int, int>> MatchBinaryDescriptors(const cv::Mat& query, const cv::Mat& train, bool cross_check,
                                                        double ratio);

// Matching guided by a predicted displacement, as ORB-SLAM searches by its motion model: each feature of `frame`
// is matched only among the features of `key` inside a window around where the prediction puts it (key x = frame x -
// predicted_dx, key y = frame y, within half_width / half_height px, widened by zoom times the feature's distance from
// centre across and up or down) and at a pyramid level at most
// max_level_difference from its own; the best by Hamming distance is kept when it is at most max_distance and below
// ratio times the second best among those candidates (no second: kept), and each feature of `key` keeps only its
// best such match. Features must come from an ORB matcher's Extract (CreateOrbMatcher). points0: frame, points1: key.
struct MatchWindow {
  double predicted_dx = 0.0;  // x_frame - x_key, px
  double half_width = 4.0;
  double half_height = 6.0;
  // The window grows with the distance from `centre` by this share of it (0: none): a robot moving along its route
  // sees the scene grow or shrink about the direction it moves (a key image ahead or behind the frame).
  double zoom = 0.0;
  cv::Point2f centre;
  int max_level_difference = 1;
  int max_distance = 64;
  double ratio = 0.9;
};
TentativeMatches MatchOrbInWindow(const ImageFeatures& frame, const ImageFeatures& key, const MatchWindow& window);

}  // namespace vmap
