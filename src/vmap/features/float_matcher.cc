#include "vmap/features/float_matcher.h"

#include <algorithm>
#include <limits>

namespace vmap {

std::vector<FloatMatch> MatchFloatDescriptors(const cv::Mat& query, const cv::Mat& train, float min_similarity) {
  std::vector<FloatMatch> matches;
  if (query.empty() || train.empty()) return matches;
  CV_Assert(query.type() == CV_32F && train.type() == CV_32F && query.cols == train.cols);

  // Best train row of every query row, and best query row of every train row, over all blocks.
  std::vector<int> best_train(query.rows, -1);
  std::vector<float> best_train_similarity(query.rows, -std::numeric_limits<float>::infinity());
  std::vector<int> best_query(train.rows, -1);
  std::vector<float> best_query_similarity(train.rows, -std::numeric_limits<float>::infinity());

  // 256 query rows at a time: a 256 x 4096 block of similarities is 4 MB.
  constexpr int kBlockRows = 256;
  cv::Mat similarities;
  for (int begin = 0; begin < query.rows; begin += kBlockRows) {
    const int end = std::min(query.rows, begin + kBlockRows);
    cv::gemm(query.rowRange(begin, end), train, 1.0, cv::noArray(), 0.0, similarities, cv::GEMM_2_T);
    for (int i = begin; i < end; ++i) {
      const float* row = similarities.ptr<float>(i - begin);
      for (int j = 0; j < train.rows; ++j) {
        const float s = row[j];
        if (s > best_train_similarity[i]) {
          best_train_similarity[i] = s;
          best_train[i] = j;
        }
        if (s > best_query_similarity[j]) {
          best_query_similarity[j] = s;
          best_query[j] = i;
        }
      }
    }
  }
  for (int i = 0; i < query.rows; ++i) {
    const int j = best_train[i];
    if (j >= 0 && best_query[j] == i && best_train_similarity[i] >= min_similarity) {
      matches.push_back({i, j, best_train_similarity[i]});
    }
  }
  return matches;
}

}  // namespace vmap
