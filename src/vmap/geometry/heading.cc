#include "vmap/geometry/heading.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "vmap/core/error.h"
#include "vmap/geometry/relative_pose.h"

namespace vmap {

void HeadingOptions::Check() const {
  if (!(window_px > 0.0 && window_px <= 10000.0)) {
    throw OptionError("window_px", "must be in (0, 10000] pixels (default 20)");
  }
  if (!(window_dy_px >= 0.0 && window_dy_px <= 10000.0)) {
    throw OptionError("window_dy_px", "must be 0 to 10000 pixels (0 = by x alone; default 40)");
  }
  if (min_votes < 1 || min_votes > 100000) throw OptionError("min_votes", "must be 1 to 100000 (default 3)");
}

std::string HeadingMethodName(HeadingMethod method) { return EnumToName(kHeadingMethodNames, method); }

HeadingEstimate EstimateHeading(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                const HeadingOptions& options, const Camera* camera) {
  options.Check();
  CV_Assert(points0.size() == points1.size());
  struct Vote {
    double dx, dy;
    int match;
  };
  std::vector<Vote> votes;
  votes.reserve(points0.size());
  for (size_t i = 0; i < points0.size(); ++i) {
    const double dx = points1[i].x - points0[i].x, dy = points1[i].y - points0[i].y;
    if (!std::isfinite(dx) || !std::isfinite(dy)) continue;
    votes.push_back({dx, dy, static_cast<int>(i)});
  }
  HeadingEstimate estimate;
  estimate.num_voters = static_cast<int>(votes.size());
  // Ties on dx broken by match index, so that the order, and the result, never depends on the sort.
  std::sort(votes.begin(), votes.end(),
            [](const Vote& a, const Vote& b) { return a.dx < b.dx || (a.dx == b.dx && a.match < b.match); });
  // The densest window [dx_begin, dx_begin + window_px] (x [dy_begin, dy_begin + window_dy_px]): two pointers
  // over the displacements sorted by dx, and within each dx window that could beat the best, over its dy.
  std::vector<int> best;  // indices into votes
  std::vector<int> column;
  for (size_t begin = 0, end = 0; begin < votes.size(); ++begin) {
    end = std::max(end, begin);
    while (end < votes.size() && votes[end].dx - votes[begin].dx <= options.window_px) ++end;
    if (end - begin <= best.size()) continue;
    column.clear();
    for (size_t k = begin; k < end; ++k) column.push_back(static_cast<int>(k));
    if (options.window_dy_px > 0.0) {
      std::sort(column.begin(), column.end(), [&](int a, int b) {
        return votes[a].dy < votes[b].dy || (votes[a].dy == votes[b].dy && a < b);
      });
      size_t best_low = 0, best_high = 0;
      for (size_t low = 0, high = 0; low < column.size(); ++low) {
        high = std::max(high, low);
        while (high < column.size() && votes[column[high]].dy - votes[column[low]].dy <= options.window_dy_px) ++high;
        if (high - low > best_high - best_low) {
          best_low = low;
          best_high = high;
        }
      }
      if (best_high - best_low <= best.size()) continue;
      column = std::vector<int>(column.begin() + best_low, column.begin() + best_high);
    }
    best = column;
  }
  const int count = static_cast<int>(best.size());
  if (count < options.min_votes) return estimate;
  estimate.method = HeadingMethod::kDisplacementMode;
  estimate.votes = count;
  estimate.confidence = static_cast<double>(count) / static_cast<double>(votes.size());
  std::vector<double> window;
  window.reserve(count);
  for (int k : best) window.push_back(votes[k].dx);
  estimate.px = Median(std::move(window));  // geometry/relative_pose.h
  if (camera != nullptr) {
    std::vector<cv::Point2f> winners0, winners1;
    winners0.reserve(count);
    winners1.reserve(count);
    for (int k : best) {
      winners0.push_back(points0[votes[k].match]);
      winners1.push_back(points1[votes[k].match]);
    }
    const std::vector<cv::Point2d> rays0 = NormalizePoints(*camera, winners0);
    const std::vector<cv::Point2d> rays1 = NormalizePoints(*camera, winners1);
    std::vector<double> bearings;
    bearings.reserve(count);
    for (int k = 0; k < count; ++k) bearings.push_back(std::atan(rays1[k].x) - std::atan(rays0[k].x));
    estimate.deg = Median(std::move(bearings)) * 180.0 / M_PI;
  }
  return estimate;
}

}  // namespace vmap
