#include "vmap/features/float_matcher.h"

#include <algorithm>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>

namespace vmap {

namespace {

// Similarities are computed tile by tile: kTileRows query rows x kTileCols train rows (1 MB), scanned for
// both nearest neighbours while the tile is still in cache. cv::gemm hands products of at least 100 rows to
// the BLAS OpenCV is built with (OpenBLAS, dispatched at run time to the CPU's best kernels) and computes
// smaller ones itself, 25x slower; so every product has at least kMinRows rows.
//
// Measured on 512 x 4096 unit 64-d descriptors, one thread of a loaded Zen 3 core (min of 40 runs, gemm +
// scan): cv::gemm 2.8-3.0 ms (74 ms with 32- or 64-row products); cblas_sgemm (OpenBLAS) 2.8-3.0 ms;
// LibTorch mm 2.9-3.1 ms; Eigen 3.4 6.5-14.5 ms, compiled for SSE2 or with -mavx2 -mfma alike. The scan
// alone is 0.45 ms. So a 4096 x 4096 pair (XFeat's upstream top-k) takes about 23 ms on one core. The
// previous version (256 whole rows at a time, scalar scan) took 3.7 ms on 512 x 4096 and 7.6 ms on 60 x 4096
// (this one: 0.67 ms).
constexpr int kTileRows = 256;
constexpr int kTileCols = 1024;
constexpr int kMinRows = 128;

}  // namespace

std::vector<FloatMatch> MatchFloatDescriptors(const cv::Mat& query, const cv::Mat& train, float min_similarity) {
  std::vector<FloatMatch> matches;
  if (query.empty() || train.empty()) return matches;
  CV_Assert(query.type() == CV_32F && train.type() == CV_32F && query.cols == train.cols);
  constexpr float kLowest = -std::numeric_limits<float>::infinity();

  // Best train row of every query row, and best query row of every train row, over all tiles.
  std::vector<int> best_train(query.rows, -1);
  std::vector<float> best_train_similarity(query.rows, kLowest);
  std::vector<int> best_query(train.rows, -1);
  std::vector<float> best_query_similarity(train.rows, kLowest);

  // A query of fewer than kMinRows rows is padded with zero rows, whose similarities are never read.
  cv::Mat padded;
  const cv::Mat* rows = &query;
  if (query.rows < kMinRows) {
    padded = cv::Mat::zeros(kMinRows, query.cols, CV_32F);
    query.copyTo(padded.rowRange(0, query.rows));
    rows = &padded;
  }
  cv::Mat tile_memory(kTileRows + kMinRows, kTileCols, CV_32F);
  for (int row_begin = 0; row_begin < query.rows;) {
    // The last product takes the remaining rows when fewer than kMinRows would be left after this one.
    int row_end = std::min(query.rows, row_begin + kTileRows);
    if (query.rows - row_end < kMinRows) row_end = query.rows;
    const int product_rows = std::max(row_end - row_begin, std::min(kMinRows, rows->rows - row_begin));
    for (int col_begin = 0; col_begin < train.rows; col_begin += kTileCols) {
      const int col_end = std::min(train.rows, col_begin + kTileCols);
      const int width = col_end - col_begin;
      cv::Mat tile = tile_memory(cv::Rect(0, 0, width, product_rows));
      cv::gemm(rows->rowRange(row_begin, row_begin + product_rows), train.rowRange(col_begin, col_end), 1.0,
               cv::noArray(), 0.0, tile, cv::GEMM_2_T);
      float* column_best = best_query_similarity.data() + col_begin;
      int* column_index = best_query.data() + col_begin;
      for (int i = row_begin; i < row_end; ++i) {
        const float* similarity = tile.ptr<float>(i - row_begin);
        // 4 lanes at a time (SSE2 / NEON): the row's maximum, and each column's best row so far. Strict
        // comparisons keep the lowest index among equal similarities, in rows as in columns.
        const cv::v_int32x4 row_index = cv::v_setall_s32(i);
        cv::v_float32x4 row_max = cv::v_setall_f32(kLowest);
        int j = 0;
        for (; j + 4 <= width; j += 4) {
          const cv::v_float32x4 s = cv::v_load(similarity + j);
          row_max = cv::v_max(row_max, s);
          const cv::v_float32x4 best = cv::v_load(column_best + j);
          const cv::v_float32x4 better = s > best;
          cv::v_store(column_best + j, cv::v_select(better, s, best));
          cv::v_store(column_index + j,
                      cv::v_select(cv::v_reinterpret_as_s32(better), row_index, cv::v_load(column_index + j)));
        }
        float maximum = cv::v_reduce_max(row_max);
        for (; j < width; ++j) {
          maximum = std::max(maximum, similarity[j]);
          if (similarity[j] > column_best[j]) {
            column_best[j] = similarity[j];
            column_index[j] = i;
          }
        }
        if (maximum > best_train_similarity[i]) {
          best_train_similarity[i] = maximum;
          best_train[i] = col_begin + static_cast<int>(std::find(similarity, similarity + width, maximum) - similarity);
        }
      }
    }
    row_begin = row_end;
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
