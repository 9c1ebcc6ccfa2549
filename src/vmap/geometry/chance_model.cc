#include "vmap/geometry/chance_model.h"

#include <algorithm>
#include <cmath>

namespace vmap {

namespace {

constexpr int kSampleSize = 7;            // matches that determine F (the 7-point algorithm)
constexpr double kModelsPerSample = 3.0;  // real roots of the 7-point algorithm's cubic, at most
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Distances below this are float rounding of the coordinates (pixel coordinates near 1000 are exact to about
// 1e-4 px), not a tighter fit: counted as this, so that a perfect fit gives a finite, very low NFA.
constexpr double kLeastDistance = 1e-4;
// Random pairings of a pair's points that measure alpha on them (all of them when there are fewer): enough
// for a share of 1e-3 to be known within about 20 %.
constexpr long kRandomPairs = 20000;

double Log10Binomial(int n, int k) {
  return (std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0)) / std::log(10.0);
}

// An epipolar line with the length of its normal, which the distance divides by.
struct EpipolarLine {
  explicit EpipolarLine(const cv::Vec3d& l) : line(l), norm(std::hypot(l[0], l[1])) {}
  // The distance of a point from the line, or infinity when the line is undefined (a point at an epipole).
  double Distance(const cv::Point2f& p) const {
    if (!(norm > 0.0)) return kInfinity;
    return std::abs(line[0] * p.x + line[1] * p.y + line[2]) / norm;
  }
  cv::Vec3d line;
  double norm;
};

// Each match's two epipolar lines: F x0 in image 1 and F^T x1 in image 0.
void EpipolarLines(const cv::Matx33d& F, const std::vector<cv::Point2f>& points0,
                   const std::vector<cv::Point2f>& points1, std::vector<EpipolarLine>* lines1,
                   std::vector<EpipolarLine>* lines0) {
  const cv::Matx33d Ft = F.t();
  lines1->reserve(points0.size());
  lines0->reserve(points1.size());
  for (const cv::Point2f& p : points0) lines1->emplace_back(F * cv::Vec3d(p.x, p.y, 1.0));
  for (const cv::Point2f& p : points1) lines0->emplace_back(Ft * cv::Vec3d(p.x, p.y, 1.0));
}

// std::lower_bound's index, with a conditional move where it has a branch (the values fall anywhere among the
// thresholds: the branch would be mispredicted half the time).
size_t FirstNotBelow(const std::vector<double>& sorted, double value) {
  if (sorted.empty()) return 0;
  const double* base = sorted.data();
  for (size_t length = sorted.size(); length > 1;) {
    const size_t half = length / 2;
    base += base[half] < value ? half : 0;
    length -= half;
  }
  return static_cast<size_t>(base - sorted.data()) + (*base < value);
}

// How many `values` have each index as FirstNotBelow in `sorted` (counts[sorted.size()]: above them all).
// Eight searches go side by side, step by step: a search's steps wait on each other's loads, eight searches'
// do not (docs/measurements/code-choices.md, "The chance model's counts").
std::vector<int> CountByFirstNotBelow(const std::vector<double>& sorted, const std::vector<double>& values) {
  std::vector<int> counts(sorted.size() + 1, 0);
  constexpr size_t kSideBySide = 8;
  size_t v = 0;
  if (!sorted.empty()) {
    for (; v + kSideBySide <= values.size(); v += kSideBySide) {
      const double* base[kSideBySide];
      for (size_t b = 0; b < kSideBySide; ++b) base[b] = sorted.data();
      for (size_t length = sorted.size(); length > 1;) {
        const size_t half = length / 2;
        for (size_t b = 0; b < kSideBySide; ++b) base[b] += base[b][half] < values[v + b] ? half : 0;
        length -= half;
      }
      for (size_t b = 0; b < kSideBySide; ++b) {
        ++counts[static_cast<size_t>(base[b] - sorted.data()) + (*base[b] < values[v + b])];
      }
    }
  }
  for (; v < values.size(); ++v) ++counts[FirstNotBelow(sorted, values[v])];
  return counts;
}

// RandomInlierProbability for one image size, with the diagonal computed once (it is asked at every k).
class StripProbability {
 public:
  explicit StripProbability(cv::Size size)
      : valid_(size.width > 0 && size.height > 0),
        diagonal_(std::hypot(size.width, size.height)),
        area_(static_cast<double>(size.width) * size.height) {}
  double operator()(double distance) const { return valid_ ? std::min(1.0, 2.0 * distance * diagonal_ / area_) : 1.0; }

 private:
  bool valid_;
  double diagonal_, area_;
};

}  // namespace

double RandomInlierProbability(double distance, cv::Size size) { return StripProbability(size)(distance); }

double Log10FalseAlarms(int num_matches, int num_inliers, double alpha, double num_hypotheses) {
  if (num_inliers <= kSampleSize || num_inliers > num_matches) return kInfinity;
  const double tests = std::log10(std::max(num_hypotheses, 1.0) * kModelsPerSample * (num_matches - kSampleSize));
  const double chance = alpha > 0.0 ? (num_inliers - kSampleSize) * std::log10(std::min(alpha, 1.0)) : -kInfinity;
  return tests + Log10Binomial(num_matches, num_inliers) + Log10Binomial(num_inliers, kSampleSize) + chance;
}

double EpipolarDistance(const cv::Matx33d& F, const cv::Point2f& p0, const cv::Point2f& p1) {
  const cv::Vec3d x0(p0.x, p0.y, 1.0), x1(p1.x, p1.y, 1.0);
  return std::max(EpipolarLine(F * x0).Distance(p1), EpipolarLine(F.t() * x1).Distance(p0));
}

ChanceOfMatches ChanceOfFundamental(const cv::Matx33d& F, const std::vector<cv::Point2f>& points0,
                                    const std::vector<cv::Point2f>& points1, cv::Size size0, cv::Size size1,
                                    double num_hypotheses) {
  CV_Assert(points0.size() == points1.size());
  ChanceOfMatches best;
  const int n = static_cast<int>(points0.size());
  if (n <= kSampleSize) return best;
  // Each point's line once: the random pairings below would otherwise compute them 40,000 times (the
  // distances are the same, bit for bit, as EpipolarDistance's).
  std::vector<EpipolarLine> lines1, lines0;
  EpipolarLines(F, points0, points1, &lines1, &lines0);
  auto distance = [&](int i, int j) {
    return std::max(lines1[i].Distance(points1[j]), lines0[j].Distance(points0[i]));
  };
  std::vector<double> distances(n);
  for (int i = 0; i < n; ++i) distances[i] = distance(i, i);
  std::sort(distances.begin(), distances.end());
  // The k-th smallest distance is the threshold e of the k nearest matches (clamping keeps the order).
  for (double& d : distances) d = std::max(d, kLeastDistance);
  // Real unrelated images do not spread their matched points uniformly: they cluster where the texture is, and
  // an F whose epipoles sit in such clusters puts every clustered point near its line. So alpha(e) is also
  // measured on the pair's own points, paired at random (the frame point of one match with the key point of
  // another: what the null hypothesis says a match is), and the larger of the two probabilities is used.
  // It is needed only at the n thresholds above: each random pairing is counted under the first threshold it
  // does not exceed, and the running sum gives how many are within each. The same counts as sorting the
  // pairings, faster (docs/measurements/code-choices.md, "The chance model's counts").
  const long all_pairs = static_cast<long>(n) * (n - 1);
  std::vector<double> paired(static_cast<size_t>(std::min<long>(all_pairs, kRandomPairs)));
  cv::RNG rng(0x5eed);  // deterministic: the same pair always gives the same score
  for (size_t s = 0; s < paired.size(); ++s) {
    int i, j;
    if (all_pairs <= kRandomPairs) {
      i = static_cast<int>(s) / (n - 1);
      j = static_cast<int>(s) % (n - 1);
    } else {
      i = rng.uniform(0, n);
      j = rng.uniform(0, n - 1);
    }
    j += j >= i;
    paired[s] = distance(i, j);
  }
  const int num_shuffled = static_cast<int>(paired.size());
  std::vector<int> within_threshold = CountByFirstNotBelow(distances, paired);  // then [k]: <= distances[k]
  for (int k = 1; k <= n; ++k) within_threshold[k] += within_threshold[k - 1];
  const StripProbability strip0(size0), strip1(size1);
  // The k nearest for every k: C(n, k) and C(k, 7) updated from k to k + 1 rather than recomputed.
  const double tests = std::log10(std::max(num_hypotheses, 1.0) * kModelsPerSample * (n - kSampleSize));
  double log_n_choose_k = Log10Binomial(n, kSampleSize + 1);
  double log_k_choose_7 = Log10Binomial(kSampleSize + 1, kSampleSize);
  for (int k = kSampleSize + 1; k <= n; ++k) {
    if (k > kSampleSize + 1) {
      log_n_choose_k += std::log10(static_cast<double>(n - k + 1) / k);
      log_k_choose_7 += std::log10(static_cast<double>(k) / (k - kSampleSize));
    }
    const double e = distances[k - 1];
    if (!std::isfinite(e)) break;
    const double shuffled_share = static_cast<double>(within_threshold[k - 1]) / num_shuffled;
    const double alpha = std::max(std::min(strip0(e), strip1(e)), shuffled_share);
    if (alpha >= 1.0) break;  // every match explained: nothing is unlikely any more
    const double log10_nfa = tests + log_n_choose_k + log_k_choose_7 + (k - kSampleSize) * std::log10(alpha);
    if (log10_nfa < best.log10_nfa) best = {log10_nfa, k, e};
  }
  return best;
}

}  // namespace vmap
