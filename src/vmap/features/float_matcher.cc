#include "vmap/features/float_matcher.h"

#include <algorithm>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>

namespace vmap {

namespace {

// Similarities are computed tile by tile: kTileRows query rows x kTileCols train rows (512 KB), scanned while
// the tile is still in cache (half a core's L2 here; larger and other tiles were no faster). cv::gemm hands
// products of at least 100 rows to the BLAS OpenCV is built with (OpenBLAS, dispatched at run time to the CPU's
// best kernels) and computes smaller ones itself, far slower; so every product has at least kMinRows rows.
// cv::gemm was as fast as OpenBLAS called directly and LibTorch, and faster than Eigen
// (docs/measurements/code-choices.md, "Float matching: tiles and the matrix product").
constexpr int kTileRows = 256;
constexpr int kTileCols = 512;
constexpr int kMinRows = 128;
// The bound's set-up (the train rows' principal axes) pays off from about this many train rows.
constexpr int kMinTrainRowsToPrune = 1024;
constexpr float kLowest = -std::numeric_limits<float>::infinity();

// The best partner of every query row and of every train row among the pairs offered so far. Offers come in
// increasing row order for each column and increasing column order for each row, and only a strictly better
// similarity replaces the best: ties keep the lowest index.
class MutualBest {
 public:
  MutualBest(int query_rows, int train_rows)
      : best_train_(query_rows, -1),
        best_train_similarity_(query_rows, kLowest),
        best_query_(train_rows, -1),
        best_query_similarity_(train_rows, kLowest) {}

  void Offer(int i, int j, float similarity) {
    if (similarity > best_train_similarity_[i]) {
      best_train_similarity_[i] = similarity;
      best_train_[i] = j;
    }
    if (similarity > best_query_similarity_[j]) {
      best_query_similarity_[j] = similarity;
      best_query_[j] = i;
    }
  }

  // One tile row at once: `similarity[0..width)` are row i's similarities with train rows col_begin...
  void OfferRow(int i, int col_begin, const float* similarity, int width) {
    float* column_best = best_query_similarity_.data() + col_begin;
    int* column_index = best_query_.data() + col_begin;
    // 4 lanes at a time (SSE2 / NEON): the row's maximum, and each column's best row so far.
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
    if (maximum > best_train_similarity_[i]) {
      best_train_similarity_[i] = maximum;
      best_train_[i] = col_begin + static_cast<int>(std::find(similarity, similarity + width, maximum) - similarity);
    }
  }

  std::vector<FloatMatch> Mutual(float min_similarity) const {
    std::vector<FloatMatch> matches;
    for (int i = 0; i < static_cast<int>(best_train_.size()); ++i) {
      const int j = best_train_[i];
      if (j >= 0 && best_query_[j] == i && best_train_similarity_[i] >= min_similarity) {
        matches.push_back({i, j, best_train_similarity_[i]});
      }
    }
    return matches;
  }

 private:
  std::vector<int> best_train_;
  std::vector<float> best_train_similarity_;
  std::vector<int> best_query_;
  std::vector<float> best_query_similarity_;
};

// Calls visit(row_begin, row_end, col_begin, tile) for every tile of a * b^T (rows of a against rows of b),
// row tiles outer, column tiles inner, both ascending.
template <typename Visit>
void ForEachProductTile(const cv::Mat& a, const cv::Mat& b, Visit visit) {
  // A matrix of fewer than kMinRows rows is padded with zero rows, whose products are never read.
  cv::Mat padded;
  const cv::Mat* rows = &a;
  if (a.rows < kMinRows) {
    padded = cv::Mat::zeros(kMinRows, a.cols, CV_32F);
    a.copyTo(padded.rowRange(0, a.rows));
    rows = &padded;
  }
  cv::Mat tile_memory(kTileRows + kMinRows, kTileCols, CV_32F);
  for (int row_begin = 0; row_begin < a.rows;) {
    // The last product takes the remaining rows when fewer than kMinRows would be left after this one.
    int row_end = std::min(a.rows, row_begin + kTileRows);
    if (a.rows - row_end < kMinRows) row_end = a.rows;
    const int product_rows = std::max(row_end - row_begin, std::min(kMinRows, rows->rows - row_begin));
    for (int col_begin = 0; col_begin < b.rows; col_begin += kTileCols) {
      const int col_end = std::min(b.rows, col_begin + kTileCols);
      cv::Mat tile = tile_memory(cv::Rect(0, 0, col_end - col_begin, product_rows));
      cv::gemm(rows->rowRange(row_begin, row_begin + product_rows), b.rowRange(col_begin, col_end), 1.0, cv::noArray(),
               0.0, tile, cv::GEMM_2_T);
      visit(row_begin, row_end, col_begin, tile);
    }
    row_begin = row_end;
  }
}

// Every pair's similarity: one 64-d product per pair.
void OfferAllPairs(const cv::Mat& query, const cv::Mat& train, MutualBest& best) {
  ForEachProductTile(query, train, [&](int row_begin, int row_end, int col_begin, const cv::Mat& tile) {
    for (int i = row_begin; i < row_end; ++i) best.OfferRow(i, col_begin, tile.ptr<float>(i - row_begin), tile.cols);
  });
}

float SquaredNorm(const float* row, int size) {
  float sum = 0.f;
  for (int x = 0; x < size; ++x) sum += row[x] * row[x];
  return sum;
}

// Four sums side by side: one running sum would wait on its own additions (measured in
// docs/measurements/code-choices.md, "Float matching: the bound on a projection").
float Dot(const float* a, const float* b, int size) {
  cv::v_float32x4 sum0 = cv::v_setzero_f32(), sum1 = sum0, sum2 = sum0, sum3 = sum0;
  int x = 0;
  for (; x + 16 <= size; x += 16) {
    sum0 = cv::v_fma(cv::v_load(a + x), cv::v_load(b + x), sum0);
    sum1 = cv::v_fma(cv::v_load(a + x + 4), cv::v_load(b + x + 4), sum1);
    sum2 = cv::v_fma(cv::v_load(a + x + 8), cv::v_load(b + x + 8), sum2);
    sum3 = cv::v_fma(cv::v_load(a + x + 12), cv::v_load(b + x + 12), sum3);
  }
  for (; x + 4 <= size; x += 4) sum0 = cv::v_fma(cv::v_load(a + x), cv::v_load(b + x), sum0);
  float total = cv::v_reduce_sum((sum0 + sum1) + (sum2 + sum3));
  for (; x < size; ++x) total += a[x] * b[x];
  return total;
}

// The bound's share of the width: 3/8 of the axes (24 of XFeat's 64) was the fastest of 1/4, 3/8 and 1/2 on
// XFeat's pairs (`xfeat_bench --float-matching`; docs/measurements/code-choices.md, "Float matching: the bound
// on a projection").
int BoundAxes(int dims) { return dims * 3 / 8; }

// The bound pays off where the floor is high and the descriptors wide. Below a floor of ~0.5 nearly every pair
// passes, and small sets are fast either way.
bool UseBound(const cv::Mat& query, const cv::Mat& train, float min_similarity) {
  return min_similarity >= 0.5f && BoundAxes(query.cols) >= 8 && query.rows >= kMinRows &&
         train.rows >= kMinTrainRowsToPrune;
}

}  // namespace

// Only pairs with a similarity of at least `min_similarity` can be matches, and they are a small share of all
// pairs (a fraction of a percent of XFeat's on lab_floor). A projection P onto k orthonormal axes
// never lengthens a vector, so a pair can reach the floor only if
//   |P q - P t|^2 <= |q - t|^2 = |q|^2 + |t|^2 - 2 q.t <= |q|^2 + |t|^2 - 2 min_similarity,
// which, with the projections augmented by two columns, is the sign of one k+2-wide product:
//   [Pq, 1, (|q|^2 - |Pq|^2)/2 - min_similarity] . [Pt, (|t|^2 - |Pt|^2)/2, 1] >= 0.
// The axes are the train rows' principal ones, where descriptors differ most, so the bound prunes hard;
// the pairs it keeps get their exact similarity. The result is the exhaustive one (up to float rounding in
// a similarity: the dot products are summed in another order).
//
// The train side (its axes and augmented projections) depends on the train rows alone.
struct FloatTrainBound {
  cv::Mat basis;              // k x width, the principal axes by decreasing variance
  cv::Mat rows;               // train rows x (k + 2): [Pt, (|t|^2 - |Pt|^2)/2, 1]
  double largest_norm = 0.0;  // the largest |t|^2
};

namespace {

FloatTrainBound PrepareTrainBound(const cv::Mat& train) {
  const int axes = BoundAxes(train.cols);
  FloatTrainBound out;
  cv::Mat mean, covariance, eigenvalues, eigenvectors;
  cv::reduce(train, mean, 0, cv::REDUCE_AVG);
  cv::gemm(train, train, 1.0 / train.rows, cv::noArray(), 0.0, covariance, cv::GEMM_1_T);
  covariance -= mean.t() * mean;
  cv::eigen(covariance, eigenvalues, eigenvectors);  // rows, by decreasing eigenvalue
  out.basis = eigenvectors.rowRange(0, axes).clone();
  out.rows.create(train.rows, axes + 2, CV_32F);
  cv::Mat projection = out.rows.colRange(0, axes);
  cv::gemm(train, out.basis, 1.0, cv::noArray(), 0.0, projection, cv::GEMM_2_T);
  for (int j = 0; j < train.rows; ++j) {
    float* row = out.rows.ptr<float>(j);
    const float norm = SquaredNorm(train.ptr<float>(j), train.cols);
    out.largest_norm = std::max(out.largest_norm, static_cast<double>(norm));
    row[axes] = 0.5f * (norm - SquaredNorm(row, axes));
    row[axes + 1] = 1.f;
  }
  return out;
}

void OfferPairsAboveFloor(const cv::Mat& query, const cv::Mat& train, const FloatTrainBound& train_bound,
                          float min_similarity, MutualBest& best) {
  const int dims = query.cols;
  const int axes = train_bound.basis.rows;
  // Float rounding in the k+2 terms (each at most about |q|^2 + |t|^2) is far below this margin; a pair let
  // through by it only costs an exact similarity.
  double largest_norm = train_bound.largest_norm;
  cv::Mat query_bound(query.rows, axes + 2, CV_32F);
  cv::Mat query_projection = query_bound.colRange(0, axes);
  cv::gemm(query, train_bound.basis, 1.0, cv::noArray(), 0.0, query_projection, cv::GEMM_2_T);
  std::vector<float> query_residual(query.rows);
  for (int i = 0; i < query.rows; ++i) {
    const float norm = SquaredNorm(query.ptr<float>(i), dims);
    largest_norm = std::max(largest_norm, static_cast<double>(norm));
    query_residual[i] = 0.5f * (norm - SquaredNorm(query_bound.ptr<float>(i), axes));
  }
  const float margin = static_cast<float>(1e-4 * (1.0 + 2.0 * largest_norm));
  for (int i = 0; i < query.rows; ++i) {
    float* row = query_bound.ptr<float>(i);
    row[axes] = 1.f;
    row[axes + 1] = query_residual[i] - min_similarity + margin;
  }

  auto offer_tile = [&](int row_begin, int row_end, int col_begin, const cv::Mat& tile) {
    const int width = tile.cols;
    for (int i = row_begin; i < row_end; ++i) {
      const float* bound = tile.ptr<float>(i - row_begin);
      const float* q = query.ptr<float>(i);
      int j = 0;
      for (; j + 16 <= width; j += 16) {
        // 16 bounds at a time; nearly all are negative (the pair cannot reach the floor).
        const cv::v_float32x4 b0 = cv::v_load(bound + j), b1 = cv::v_load(bound + j + 4);
        const cv::v_float32x4 b2 = cv::v_load(bound + j + 8), b3 = cv::v_load(bound + j + 12);
        // All negative when every sign bit is set in their bitwise and.
        if (cv::v_signmask(b0 & b1 & b2 & b3) == 0xF) continue;
        const int negative =
            cv::v_signmask(b0) | cv::v_signmask(b1) << 4 | cv::v_signmask(b2) << 8 | cv::v_signmask(b3) << 12;
        // The others by their bits, lowest first: one branch per pair let through rather than one per bound,
        // the faster (docs/measurements/code-choices.md, "Float matching: the bound on a projection").
        for (unsigned let_through = ~negative & 0xFFFFu; let_through != 0; let_through &= let_through - 1) {
          const int x = j + __builtin_ctz(let_through);
          const float similarity = Dot(q, train.ptr<float>(col_begin + x), dims);
          if (similarity >= min_similarity) best.Offer(i, col_begin + x, similarity);
        }
      }
      for (; j < width; ++j) {
        if (bound[j] < 0.f) continue;
        const float similarity = Dot(q, train.ptr<float>(col_begin + j), dims);
        if (similarity >= min_similarity) best.Offer(i, col_begin + j, similarity);
      }
    }
  };
  ForEachProductTile(query_bound, train_bound.rows, offer_tile);
}

}  // namespace

std::vector<FloatMatch> MatchFloatDescriptors(const cv::Mat& query, const cv::Mat& train, float min_similarity) {
  return MatchFloatDescriptors(query, FloatTrainRows(train), min_similarity);  // its bound is made if used
}

FloatTrainRows::FloatTrainRows(cv::Mat rows) : rows_(std::move(rows)) {}
FloatTrainRows::~FloatTrainRows() = default;

const FloatTrainBound& FloatTrainRows::bound() const {
  std::call_once(once_, [&] { bound_ = std::make_unique<const FloatTrainBound>(PrepareTrainBound(rows_)); });
  return *bound_;
}

std::vector<FloatMatch> MatchFloatDescriptors(const cv::Mat& query, const FloatTrainRows& train, float min_similarity) {
  const cv::Mat& rows = train.rows();
  if (query.empty() || rows.empty()) return {};
  CV_Assert(query.type() == CV_32F && rows.type() == CV_32F && query.cols == rows.cols);
  MutualBest best(query.rows, rows.rows);
  if (UseBound(query, rows, min_similarity)) {
    OfferPairsAboveFloor(query, rows, train.bound(), min_similarity, best);
  } else {
    OfferAllPairs(query, rows, best);
  }
  return best.Mutual(min_similarity);
}

std::vector<FloatMatch> MatchFloatDescriptorsExhaustively(const cv::Mat& query, const cv::Mat& train,
                                                          float min_similarity) {
  if (query.empty() || train.empty()) return {};
  CV_Assert(query.type() == CV_32F && train.type() == CV_32F && query.cols == train.cols);
  MutualBest best(query.rows, train.rows);
  OfferAllPairs(query, train, best);
  return best.Mutual(min_similarity);
}

}  // namespace vmap
