#pragma once
// Mutual nearest-neighbour matching of float descriptors (the deep detectors' descriptors: XFeat, ALIKED).

#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

struct FloatMatch {
  int query = 0;           // row in `query`
  int train = 0;           // row in `train`
  float similarity = 0.f;  // dot product of the two rows (cosine similarity for unit rows)
};

// Keeps the pairs (i, j) where j is i's most similar train row, i is j's most similar query row, and their
// similarity is at least `min_similarity`. Rows are CV_32F descriptors of the same width, expected to be
// L2-normalised (then the dot product is the cosine similarity). Ties go to the lowest index. The similarity
// matrix is computed block by block (one matrix product per block), so memory stays small for any size. With
// a high `min_similarity` (>= 0.5) and wide descriptors, most pairs are ruled out by a cheaper bound first
// (float_matcher.cc); the matches are those of MatchFloatDescriptorsExhaustively.
std::vector<FloatMatch> MatchFloatDescriptors(const cv::Mat& query, const cv::Mat& train, float min_similarity);

struct FloatTrainBound;  // float_matcher.cc

// Descriptor rows matched as the train side many times (a key image against every frame of a localization):
// what the bound of MatchFloatDescriptors needs of them alone (their principal axes, their projections) is
// computed on first use and kept, about 0.4 of the rows' own memory. Thread-safe; not copyable.
class FloatTrainRows {
 public:
  explicit FloatTrainRows(cv::Mat rows);
  ~FloatTrainRows();
  FloatTrainRows(const FloatTrainRows&) = delete;
  FloatTrainRows& operator=(const FloatTrainRows&) = delete;

  const cv::Mat& rows() const { return rows_; }
  const FloatTrainBound& bound() const;

 private:
  cv::Mat rows_;
  mutable std::once_flag once_;
  mutable std::unique_ptr<const FloatTrainBound> bound_;
};

// As above, with the train side's bound kept between calls: the same matches.
std::vector<FloatMatch> MatchFloatDescriptors(const cv::Mat& query, const FloatTrainRows& train, float min_similarity);

// The same matches from every pair's similarity: the reference for tests and benchmarks.
std::vector<FloatMatch> MatchFloatDescriptorsExhaustively(const cv::Mat& query, const cv::Mat& train,
                                                          float min_similarity);

}  // namespace vmap
