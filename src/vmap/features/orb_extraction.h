#pragma once
// ORB keypoints spread over the image and over the pyramid (the extraction ORB-SLAM describes), for images where
// OpenCV's detector finds few corners: small, dark or re-lit ones (docs/localize.md, "ORB's extraction across
// lighting").

#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

struct OrbGridExtraction {
  int num_features = 500;
  double scale_factor = 1.2;
  int num_levels = 8;
  // No keypoint closer than this to the edge of its pyramid level, in that level's pixels (the descriptor reads
  // the level's reflected border beyond it).
  int border = 16;
  int cell_size = 30;          // the grid's cells at every level, in that level's pixels
  int fast_threshold = 20;     // FAST's threshold in every cell first
  int min_fast_threshold = 7;  // then in the cells where it found no corner
};

// Per pyramid level (features in proportion to the level's area): FAST (cv::FAST, non-maximum suppression) in
// each grid cell, the cells taking turns by rank of response until the level's share is reached; orientation by
// the intensity centroid of the 31 px patch; descriptors by cv::ORB::compute on these keypoints (OpenCV's rBRIEF
// on its smoothed pyramid). Keypoints in image coordinates, octave = level, size = 31 x the level's scale.
void ExtractOrbOnGrid(const cv::Mat& gray, const OrbGridExtraction& options, std::vector<cv::KeyPoint>& keypoints,
                      cv::Mat& descriptors);

}  // namespace vmap
