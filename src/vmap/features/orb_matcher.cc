#include "vmap/features/orb_matcher.h"

#include <cstdint>
#include <cstring>
#include <limits>

#include <nlohmann/json.hpp>
#include <opencv2/features2d.hpp>

#include "vmap/core/error.h"

namespace vmap {

void OrbMatcherOptions::Check() const {
  if (num_features < 1) throw InputError("--orb-features must be >= 1 (default 500)");
  if (!(scale_factor > 1.0)) throw InputError("--orb-scale-factor must be > 1 (default 1.2)");
  if (num_levels < 1) throw InputError("--orb-levels must be >= 1 (default 8)");
  if (edge_threshold < 0) throw InputError("--orb-edge-threshold must be >= 0 (default 31)");
  if (fast_threshold < 1) throw InputError("--orb-fast-threshold must be >= 1 (default 20)");
  if (ratio < 0.0 || ratio > 1.0) throw InputError("--ratio must be in [0, 1] (0 disables the ratio test)");
}

namespace {

class OrbFeatures : public ImageFeatures {
 public:
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // CV_8U, 32 bytes per row
  cv::Size size;
  int num_features() const override { return static_cast<int>(keypoints.size()); }
  cv::Size image_size() const override { return size; }
};

class OrbMatcher : public Matcher {
 public:
  explicit OrbMatcher(const OrbMatcherOptions& options) : options_(options) { options_.Check(); }

  std::string name() const override { return "orb"; }

  std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const override {
    // A detector per call: cv::ORB is not documented as thread-safe, and creating one is cheap.
    cv::Ptr<cv::ORB> orb = cv::ORB::create(options_.num_features, static_cast<float>(options_.scale_factor),
                                           options_.num_levels, options_.edge_threshold, 0, 2,
                                           cv::ORB::HARRIS_SCORE, 31, options_.fast_threshold);
    auto features = std::make_shared<OrbFeatures>();
    features->size = gray.size();
    orb->detectAndCompute(gray, cv::noArray(), features->keypoints, features->descriptors);
    if (features->descriptors.empty()) features->keypoints.clear();
    return features;
  }

  TentativeMatches Match(const ImageFeatures& features0, const ImageFeatures& features1) const override {
    const auto& a = static_cast<const OrbFeatures&>(features0);
    const auto& b = static_cast<const OrbFeatures&>(features1);
    TentativeMatches matches;
    if (a.descriptors.empty() || b.descriptors.empty()) return matches;
    const auto pairs = MatchBinaryDescriptors(a.descriptors, b.descriptors, options_.cross_check, options_.ratio);
    matches.points0.reserve(pairs.size());
    matches.points1.reserve(pairs.size());
    for (const auto& [i, j] : pairs) {
      matches.points0.push_back(a.keypoints[i].pt);
      matches.points1.push_back(b.keypoints[j].pt);
    }
    return matches;
  }

  std::string DescribeOptionsJson() const override {
    return nlohmann::json{{"type", "orb"},
                          {"num_features", options_.num_features},
                          {"scale_factor", options_.scale_factor},
                          {"num_levels", options_.num_levels},
                          {"edge_threshold", options_.edge_threshold},
                          {"fast_threshold", options_.fast_threshold},
                          {"cross_check", options_.cross_check},
                          {"ratio", options_.ratio}}
        .dump();
  }

 private:
  OrbMatcherOptions options_;
};

// Hamming distance of two descriptors of `words` 64-bit words. Compiled twice: with the POPCNT instruction
// and without, picked at load time, so a generic x86-64 build still gets the fast path.
__attribute__((target_clones("popcnt", "default"))) void HammingRow(const uint64_t* query, const uint64_t* train,
                                                                    int num_train, int words, int* distances) {
  if (words == 4) {  // ORB: 256 bits
    for (int j = 0; j < num_train; ++j) {
      const uint64_t* t = train + 4 * j;
      distances[j] = __builtin_popcountll(query[0] ^ t[0]) + __builtin_popcountll(query[1] ^ t[1]) +
                     __builtin_popcountll(query[2] ^ t[2]) + __builtin_popcountll(query[3] ^ t[3]);
    }
    return;
  }
  for (int j = 0; j < num_train; ++j) {
    int d = 0;
    for (int w = 0; w < words; ++w) d += __builtin_popcountll(query[w] ^ train[words * j + w]);
    distances[j] = d;
  }
}

// Copies descriptor rows into 64-bit words (cv::Mat rows need not be aligned or contiguous).
std::vector<uint64_t> PackWords(const cv::Mat& descriptors, int words) {
  std::vector<uint64_t> packed(static_cast<size_t>(descriptors.rows) * words, 0);
  for (int r = 0; r < descriptors.rows; ++r) {
    std::memcpy(packed.data() + static_cast<size_t>(r) * words, descriptors.ptr(r), descriptors.cols);
  }
  return packed;
}

}  // namespace

std::vector<std::pair<int, int>> MatchBinaryDescriptors(const cv::Mat& query, const cv::Mat& train, bool cross_check,
                                                        double ratio) {
  CV_Assert(query.type() == CV_8U && train.type() == CV_8U && query.cols == train.cols);
  const int words = (query.cols + 7) / 8;
  const std::vector<uint64_t> q = PackWords(query, words);
  const std::vector<uint64_t> t = PackWords(train, words);
  const int nq = query.rows, nt = train.rows;

  std::vector<int> best_train(nq, -1), best_distance(nq, std::numeric_limits<int>::max());
  std::vector<int> second_distance(nq, std::numeric_limits<int>::max());
  std::vector<int> best_query_for_train(nt, -1), best_distance_for_train(nt, std::numeric_limits<int>::max());
  std::vector<int> distances(nt);
  for (int i = 0; i < nq; ++i) {
    HammingRow(q.data() + static_cast<size_t>(i) * words, t.data(), nt, words, distances.data());
    int best = std::numeric_limits<int>::max(), second = best, arg = -1;
    for (int j = 0; j < nt; ++j) {
      const int d = distances[j];
      if (d < best) {
        second = best;
        best = d;
        arg = j;
      } else if (d < second) {
        second = d;
      }
    }
    // Branch-free so that it vectorises; strict '<' keeps the lowest query index on ties, as BFMatcher.
    int* column_best = best_distance_for_train.data();
    int* column_arg = best_query_for_train.data();
    for (int j = 0; j < nt; ++j) {
      const bool better = distances[j] < column_best[j];
      column_best[j] = better ? distances[j] : column_best[j];
      column_arg[j] = better ? i : column_arg[j];
    }
    best_train[i] = arg;
    best_distance[i] = best;
    second_distance[i] = second;
  }
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(nq);
  for (int i = 0; i < nq; ++i) {
    const int j = best_train[i];
    if (j < 0) continue;
    if (cross_check && best_query_for_train[j] != i) continue;
    if (ratio > 0.0 && second_distance[i] != std::numeric_limits<int>::max() &&
        !(best_distance[i] < ratio * second_distance[i])) {
      continue;
    }
    pairs.emplace_back(i, j);
  }
  return pairs;
}

std::unique_ptr<Matcher> CreateOrbMatcher(const OrbMatcherOptions& options) {
  return std::make_unique<OrbMatcher>(options);
}

}  // namespace vmap
