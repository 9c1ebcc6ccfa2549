#pragma once
// Does a homography explain a link's matches as well as its fundamental matrix? When it does, the scene
// seen is (nearly) a plane or the camera (nearly) only rotated, and F, and the pose taken from it, are
// ill-posed: many F fit the matches equally well.

#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"

namespace vmap {

struct HomographyOptions {
  // A match is explained when H maps it within this many pixels of its position in the second image.
  double threshold = 1.0;
  // H explains the matches "as well as F" when it explains at least this share of F's inliers.
  double min_share = 0.9;
  double confidence = 0.999;
  int max_iterations = 10000;
  int seed = 0;

  // The homography test as map.json records it: threshold and min_share.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct HomographyCheck {
  bool estimated = false;              // a homography could be fitted (at least 4 matches)
  cv::Matx33d H = cv::Matx33d::eye();  // x_to ~ H x_from
  int num_explained = 0;               // matches within the threshold
  double share = 0.0;                  // num_explained / matches given
  bool explains = false;               // share >= min_share
};

// Fits H robustly (OpenCV USAC, seeded) to the matches (a link's verified matches) and counts how many it
// explains.
HomographyCheck CheckHomography(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                                const HomographyOptions& options);

}  // namespace vmap
