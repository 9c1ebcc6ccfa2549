#include "vmap/features/orb_extraction.h"

#include <algorithm>
#include <cmath>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace vmap {
namespace {

constexpr int kOrbPatchSize = 31;  // rBRIEF's patch (OpenCV's default, the one its learned pattern is for)
constexpr int kOrbHalfPatch = kOrbPatchSize / 2;
constexpr int kFastRadius = 3;  // FAST's circle: a cell is searched with this margin so its own edge is covered

// Each level's share of `total`, in proportion to the level's area (1, 1/s^2, 1/s^4, ...); the top level takes
// what rounding leaves.
std::vector<int> GridLevelShares(int total, double scale_factor, int levels) {
  const double ratio = 1.0 / (scale_factor * scale_factor);
  const double first = total * (1.0 - ratio) / (1.0 - std::pow(ratio, levels));
  std::vector<int> shares(levels, 0);
  int given = 0;
  for (int level = 0; level + 1 < levels; ++level) {
    shares[level] = static_cast<int>(std::lround(first * std::pow(ratio, level)));
    given += shares[level];
  }
  shares[levels - 1] = std::max(0, total - given);
  return shares;
}

// FAST corners of one cell of `level` (cell rectangle in level pixels), at `threshold`, else at `fallback`.
std::vector<cv::KeyPoint> CellCorners(const cv::Mat& level, const cv::Rect& cell, int threshold, int fallback) {
  const cv::Rect searched = cv::Rect(cell.x - kFastRadius, cell.y - kFastRadius, cell.width + 2 * kFastRadius,
                                     cell.height + 2 * kFastRadius) &
                            cv::Rect(0, 0, level.cols, level.rows);
  std::vector<cv::KeyPoint> corners;
  for (const int t : {threshold, fallback}) {
    cv::FAST(level(searched), corners, t, /*nonmaxSuppression=*/true);
    for (cv::KeyPoint& k : corners) k.pt += cv::Point2f(static_cast<float>(searched.x), static_cast<float>(searched.y));
    corners.erase(std::remove_if(corners.begin(), corners.end(),
                                 [&](const cv::KeyPoint& k) {
                                   return !cell.contains(cv::Point(cvRound(k.pt.x), cvRound(k.pt.y)));
                                 }),
                  corners.end());
    if (!corners.empty() || fallback >= threshold) break;
  }
  return corners;
}

// Up to `wanted` of the cells' corners: every cell's strongest first, then every cell's second, ...; within a
// round the stronger first, so that a level short of its share still spreads over the image.
std::vector<cv::KeyPoint> SpreadOverCells(std::vector<std::vector<cv::KeyPoint>> cells, int wanted) {
  auto stronger = [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
    if (a.response != b.response) return a.response > b.response;
    return a.pt.y != b.pt.y ? a.pt.y < b.pt.y : a.pt.x < b.pt.x;  // deterministic among equals
  };
  for (auto& cell : cells) std::sort(cell.begin(), cell.end(), stronger);
  std::vector<cv::KeyPoint> kept;
  for (size_t rank = 0; static_cast<int>(kept.size()) < wanted; ++rank) {
    std::vector<cv::KeyPoint> round;
    for (const auto& cell : cells) {
      if (rank < cell.size()) round.push_back(cell[rank]);
    }
    if (round.empty()) break;
    std::sort(round.begin(), round.end(), stronger);
    const size_t take = std::min(round.size(), static_cast<size_t>(wanted) - kept.size());
    kept.insert(kept.end(), round.begin(), round.begin() + take);
  }
  return kept;
}

// The orientation of each keypoint: the angle (degrees) from it to the intensity centroid of the disc of radius
// 15 around it, as ORB defines it; `padded` is the level with a reflected border of kOrbHalfPatch + 1 pixels.
void SetCentroidAngles(const cv::Mat& padded, std::vector<cv::KeyPoint>& keypoints) {
  int row_half_width[kOrbHalfPatch + 1];
  for (int v = 0; v <= kOrbHalfPatch; ++v) {
    row_half_width[v] = static_cast<int>(std::floor(std::sqrt(kOrbHalfPatch * kOrbHalfPatch - v * v + 0.5)));
  }
  const int offset = kOrbHalfPatch + 1;
  for (cv::KeyPoint& k : keypoints) {
    const int cx = cvRound(k.pt.x) + offset, cy = cvRound(k.pt.y) + offset;
    long m01 = 0, m10 = 0;
    for (int v = -kOrbHalfPatch; v <= kOrbHalfPatch; ++v) {
      const uchar* row = padded.ptr<uchar>(cy + v);
      const int w = row_half_width[std::abs(v)];
      for (int u = -w; u <= w; ++u) {
        m10 += static_cast<long>(u) * row[cx + u];
        m01 += static_cast<long>(v) * row[cx + u];
      }
    }
    k.angle = cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
  }
}

}  // namespace

void ExtractOrbOnGrid(const cv::Mat& gray, const OrbGridExtraction& options, std::vector<cv::KeyPoint>& keypoints,
                      cv::Mat& descriptors) {
  keypoints.clear();
  descriptors.release();
  if (gray.empty()) return;
  const std::vector<int> shares = GridLevelShares(options.num_features, options.scale_factor, options.num_levels);
  cv::Mat level = gray;
  for (int l = 0; l < options.num_levels; ++l) {
    const double scale = std::pow(options.scale_factor, l);
    if (l > 0) {
      // Sizes as cv::ORB computes its own pyramid's (rounded from the image), so that compute() finds these
      // keypoints where they were detected.
      const cv::Size size(cvRound(gray.cols / scale), cvRound(gray.rows / scale));
      if (size.width < 1 || size.height < 1) break;
      cv::Mat next;
      cv::resize(level, next, size, 0, 0, cv::INTER_LINEAR);
      level = next;
    }
    const cv::Rect region(options.border, options.border, level.cols - 2 * options.border,
                          level.rows - 2 * options.border);
    if (region.width <= 2 * kFastRadius || region.height <= 2 * kFastRadius) break;  // and so every level above
    const int columns = std::max(1, cvRound(region.width / static_cast<double>(options.cell_size)));
    const int rows = std::max(1, cvRound(region.height / static_cast<double>(options.cell_size)));
    std::vector<std::vector<cv::KeyPoint>> cells;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < columns; ++c) {
        const int x0 = region.x + region.width * c / columns, x1 = region.x + region.width * (c + 1) / columns;
        const int y0 = region.y + region.height * r / rows, y1 = region.y + region.height * (r + 1) / rows;
        cells.push_back(
            CellCorners(level, cv::Rect(x0, y0, x1 - x0, y1 - y0), options.fast_threshold, options.min_fast_threshold));
      }
    }
    std::vector<cv::KeyPoint> kept = SpreadOverCells(std::move(cells), shares[l]);
    cv::Mat padded;
    cv::copyMakeBorder(level, padded, kOrbHalfPatch + 1, kOrbHalfPatch + 1, kOrbHalfPatch + 1, kOrbHalfPatch + 1,
                       cv::BORDER_REFLECT_101);
    SetCentroidAngles(padded, kept);
    for (cv::KeyPoint& k : kept) {
      k.pt *= static_cast<float>(scale);
      k.size = static_cast<float>(kOrbPatchSize * scale);
      k.octave = l;
      keypoints.push_back(k);
    }
  }
  if (keypoints.empty()) return;
  // cv::ORB::compute keeps the given keypoints' orientation and reads each at its octave's level; its edge
  // threshold is where it drops keypoints (image pixels), no nearer than ours.
  cv::Ptr<cv::ORB> describer =
      cv::ORB::create(options.num_features, static_cast<float>(options.scale_factor), options.num_levels,
                      options.border, 0, 2, cv::ORB::HARRIS_SCORE, kOrbPatchSize, options.fast_threshold);
  describer->compute(gray, keypoints, descriptors);
  if (descriptors.empty()) keypoints.clear();
}

}  // namespace vmap
