#include "vmap/geometry/heading.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "vmap/core/error.h"
#include "vmap/core/numeric.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void HeadingOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Heading: the horizontal offset to steer by");
  visitor.Visit(OptionField{"window_px", "--heading-window",
                            "Heading: width of the window of horizontal displacements that votes (px)"}
                    .Within(0, 10000)
                    .ExcludingMin()
                    .Unit("px"),
                window_px);
  visitor.Visit(OptionField{"window_dy_px", "--heading-window-dy",
                            "Heading: height of the window in vertical displacement (px; 0 = by x alone)"}
                    .Within(0, 10000)
                    .Unit("px")
                    .Meaning("0: by x alone"),
                window_dy_px);
  visitor.Visit(
      OptionField{"min_votes", "--heading-min-votes", "Heading: the fewest agreeing matches for an estimate"}.Within(
          1, 100000),
      min_votes);
  visitor.Visit(
      OptionField{"min_verified", "--heading-min-verified",
                  "Heading: with at least this many F-verified matches, their median displacement (0 = always the "
                  "mode of all matches)"}
          .Within(0, 100000)
          .Meaning("0: always the mode"),
      min_verified);
}

void HeadingOptions::Check() const { CheckFieldRanges(*this); }

std::string HeadingMethodName(HeadingMethod method) { return EnumToName(kHeadingMethodNames, method); }

namespace {

// The median over `matches` of the bearing of points1 minus that of points0 (degrees).
double MedianBearingDeg(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                        const std::vector<int>& matches, const Camera& camera) {
  std::vector<cv::Point2f> selected0, selected1;
  selected0.reserve(matches.size());
  selected1.reserve(matches.size());
  for (int i : matches) {
    selected0.push_back(points0[i]);
    selected1.push_back(points1[i]);
  }
  const std::vector<cv::Point2d> rays0 = NormalizePoints(camera, selected0);
  const std::vector<cv::Point2d> rays1 = NormalizePoints(camera, selected1);
  std::vector<double> bearings;
  bearings.reserve(matches.size());
  for (size_t k = 0; k < matches.size(); ++k) bearings.push_back(std::atan(rays1[k].x) - std::atan(rays0[k].x));
  return Median(std::move(bearings)) * 180.0 / M_PI;
}

}  // namespace

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
      std::sort(column.begin(), column.end(),
                [&](int a, int b) { return votes[a].dy < votes[b].dy || (votes[a].dy == votes[b].dy && a < b); });
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
  estimate.px = Median(std::move(window));
  if (camera != nullptr) {
    std::vector<int> winners;
    winners.reserve(count);
    for (int k : best) winners.push_back(votes[k].match);
    estimate.deg = MedianBearingDeg(points0, points1, winners, *camera);
  }
  return estimate;
}

HeadingEstimate EstimateHeading(const std::vector<cv::Point2f>& points0, const std::vector<cv::Point2f>& points1,
                                const std::vector<unsigned char>& verified, const HeadingOptions& options,
                                const Camera* camera) {
  options.Check();
  CV_Assert(verified.empty() || verified.size() == points0.size());
  std::vector<int> inliers;
  for (size_t i = 0; i < verified.size(); ++i) {
    if (verified[i] && std::isfinite(points1[i].x - points0[i].x)) inliers.push_back(static_cast<int>(i));
  }
  if (options.min_verified == 0 || static_cast<int>(inliers.size()) < options.min_verified) {
    return EstimateHeading(points0, points1, options, camera);
  }
  HeadingEstimate estimate;
  estimate.method = HeadingMethod::kVerifiedMedian;
  std::vector<double> dx;
  dx.reserve(inliers.size());
  for (int i : inliers) dx.push_back(points1[i].x - points0[i].x);
  estimate.px = Median(std::move(dx));
  if (camera != nullptr) estimate.deg = MedianBearingDeg(points0, points1, inliers, *camera);
  estimate.votes = static_cast<int>(inliers.size());
  estimate.num_voters = static_cast<int>(points0.size());
  estimate.confidence = static_cast<double>(estimate.votes) / static_cast<double>(estimate.num_voters);
  return estimate;
}

}  // namespace vmap
