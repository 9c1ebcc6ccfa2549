#include "vmap/features/orb_matcher.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <nlohmann/json.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"
#include "vmap/features/camera_mask.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_extraction.h"

namespace vmap {

void OrbMatcherOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"num_features", "--orb-features", "ORB: features per image"}.Within(1, 100000),
                num_features);
  visitor.Visit(
      OptionField{"scale_factor", "--orb-scale-factor", "ORB: pyramid scale factor"}.Within(1, 4).ExcludingMin(),
      scale_factor);
  visitor.Visit(OptionField{"num_levels", "--orb-levels", "ORB: pyramid levels"}.Within(1, 32), num_levels);
  visitor.Visit(OptionField{"fast_threshold", "--orb-fast-threshold", "ORB: FAST threshold"}.Within(1, 255),
                fast_threshold);
  visitor.Visit(
      OptionField{"edge_threshold", "--orb-edge-threshold", "ORB: border without features (px)"}.Within(0, 1000).Unit(
          "px"),
      edge_threshold);
  visitor.Visit(
      OptionField{"grid_cell", "--orb-grid-cell",
                  "ORB: 0 = OpenCV's detector; N = FAST per N px cell at every pyramid level, spread over cells "
                  "and levels (edge threshold per level)"}
          .Within(0, 10000)
          .Unit("px")
          .Meaning("0: OpenCV's detector"),
      grid_cell);
  visitor.Visit(OptionField{"min_fast_threshold", "--orb-min-fast-threshold",
                            "ORB grid: FAST threshold in cells where --orb-fast-threshold finds none"}
                    .Within(1, 255),
                min_fast_threshold);
  visitor.Visit(
      OptionField{"clahe_clip", "--orb-clahe", "ORB: CLAHE (8x8 tiles) before extraction, its clip limit; 0 = off"}
          .Within(0, 1000)
          .Meaning("0: off"),
      clahe_clip);
  visitor.Visit({"cross_check", "!--no-cross-check", "ORB: keep one-way best matches too"}, cross_check);
  visitor.Visit(OptionField{"ratio", "--ratio", "ORB: Lowe's ratio test (0 = off), e.g. 0.8"}.Within(0, 1).Meaning(
                    "0 disables the ratio test"),
                ratio);
}

void OrbMatcherOptions::Check() const { CheckFieldRanges(*this); }

namespace {

class OrbFeatures : public ImageFeatures {
 public:
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat binary_descriptors;  // CV_8U, 32 bytes per row
  cv::Size size;
  int num_features() const override { return static_cast<int>(keypoints.size()); }
  cv::Size image_size() const override { return size; }
  cv::Mat descriptors() const override { return binary_descriptors; }
};

// Serialised features: a header, then per keypoint x, y, size, angle, response (float32) and octave (int32),
// then the descriptor rows. Little-endian (x86/ARM), read back only by this build's matcher.
constexpr char kOrbFeaturesMagic[8] = {'v', 'm', 'a', 'p', 'O', 'R', 'B', '1'};
struct OrbFeaturesHeader {
  char magic[8];
  int32_t width, height, count, descriptor_bytes;
};
struct SerializedKeyPoint {
  float x, y, size, angle, response;
  int32_t octave;
};

void KeepWithin(const cv::Mat& keep, OrbFeatures& features) {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (size_t i = 0; i < features.keypoints.size(); ++i) {
    if (!KeptByMask(keep, features.keypoints[i].pt)) continue;
    keypoints.push_back(features.keypoints[i]);
    descriptors.push_back(features.binary_descriptors.row(static_cast<int>(i)));
  }
  features.keypoints = std::move(keypoints);
  features.binary_descriptors = descriptors;
}

class OrbMatcher : public Matcher {
 public:
  explicit OrbMatcher(const OrbMatcherOptions& options) : options_(options) { options_.Check(); }

  std::string name() const override { return "orb"; }

  std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const override { return ExtractWithin(gray, {}); }

  // OpenCV's detector looks for corners only within the mask (at every level of its pyramid), so the best
  // num_features are found where the mask keeps pixels; the grid's keypoints outside it are dropped.
  std::shared_ptr<const ImageFeatures> ExtractFrameWithin(const cv::Mat& gray, const cv::Mat&,
                                                          const cv::Mat& keep) const override {
    return ExtractWithin(gray, keep);
  }

  std::shared_ptr<const ImageFeatures> ExtractWithin(const cv::Mat& gray, const cv::Mat& keep) const {
    auto features = std::make_shared<OrbFeatures>();
    features->size = gray.size();
    if (gray.empty()) return features;
    cv::Mat image = gray;
    if (options_.clahe_clip > 0.0) {
      cv::createCLAHE(options_.clahe_clip, cv::Size(8, 8))->apply(gray, image);
    }
    if (options_.grid_cell > 0) {
      OrbGridExtraction grid;
      grid.num_features = options_.num_features;
      grid.scale_factor = options_.scale_factor;
      grid.num_levels = options_.num_levels;
      grid.border = options_.edge_threshold;
      grid.cell_size = options_.grid_cell;
      grid.fast_threshold = options_.fast_threshold;
      grid.min_fast_threshold = options_.min_fast_threshold;
      ExtractOrbOnGrid(image, grid, features->keypoints, features->binary_descriptors);
      if (!keep.empty()) KeepWithin(keep, *features);
      return features;
    }
    // OpenCV's pyramid fails on a level that rounds to no pixel (and then gave no features at all): the levels that
    // keep one are used, and the user told once.
    const int levels = LevelsWithPixels(std::min(gray.cols, gray.rows));
    if (levels < options_.num_levels && !warned_levels_.exchange(true)) {
      spdlog::warn(
          "ORB: with scale factor {} only {} of the {} levels of a {}x{} frame keep a pixel; using {} "
          "(--orb-levels, --orb-scale-factor)",
          options_.scale_factor, levels, options_.num_levels, gray.cols, gray.rows, levels);
    }
    // A detector per call: cv::ORB is not documented as thread-safe, and creating one is cheap.
    cv::Ptr<cv::ORB> orb =
        cv::ORB::create(options_.num_features, static_cast<float>(options_.scale_factor), levels,
                        options_.edge_threshold, 0, 2, cv::ORB::HARRIS_SCORE, 31, options_.fast_threshold);
    // An empty mask is OpenCV's "everywhere".
    orb->detectAndCompute(image, keep, features->keypoints, features->binary_descriptors);
    if (features->binary_descriptors.empty()) features->keypoints.clear();
    return features;
  }

  TentativeMatches Match(const ImageFeatures& features0, const ImageFeatures& features1) const override {
    const auto& a = static_cast<const OrbFeatures&>(features0);
    const auto& b = static_cast<const OrbFeatures&>(features1);
    TentativeMatches matches;
    if (a.binary_descriptors.empty() || b.binary_descriptors.empty()) return matches;
    const auto pairs =
        MatchBinaryDescriptors(a.binary_descriptors, b.binary_descriptors, options_.cross_check, options_.ratio);
    matches.points0.reserve(pairs.size());
    matches.points1.reserve(pairs.size());
    for (const auto& [i, j] : pairs) {
      matches.points0.push_back(a.keypoints[i].pt);
      matches.points1.push_back(b.keypoints[j].pt);
    }
    return matches;
  }

  std::string DescribeOptionsJson() const override {
    return TypedModelOptions<OrbMatcherOptions>(options_).ToJson().dump();  // the same keys as FromJson reads
  }

  std::string SerializeFeatures(const ImageFeatures& features) const override {
    const auto& f = static_cast<const OrbFeatures&>(features);
    OrbFeaturesHeader header{};
    std::memcpy(header.magic, kOrbFeaturesMagic, sizeof(header.magic));
    header.width = f.size.width;
    header.height = f.size.height;
    header.count = static_cast<int32_t>(f.keypoints.size());
    header.descriptor_bytes = f.binary_descriptors.empty() ? 0 : f.binary_descriptors.cols;
    std::string bytes(reinterpret_cast<const char*>(&header), sizeof(header));
    for (const cv::KeyPoint& k : f.keypoints) {
      const SerializedKeyPoint record{k.pt.x, k.pt.y, k.size, k.angle, k.response, k.octave};
      bytes.append(reinterpret_cast<const char*>(&record), sizeof(record));
    }
    for (int r = 0; r < f.binary_descriptors.rows; ++r) {
      bytes.append(reinterpret_cast<const char*>(f.binary_descriptors.ptr(r)), f.binary_descriptors.cols);
    }
    return bytes;
  }

  std::shared_ptr<const ImageFeatures> DeserializeFeatures(std::string_view bytes) const override {
    OrbFeaturesHeader header;
    if (bytes.size() < sizeof(header)) return nullptr;
    std::memcpy(&header, bytes.data(), sizeof(header));
    if (std::memcmp(header.magic, kOrbFeaturesMagic, sizeof(header.magic)) != 0 || header.count < 0 ||
        header.descriptor_bytes < 0 || header.width < 0 || header.height < 0 ||
        (header.count > 0 && header.descriptor_bytes == 0)) {
      return nullptr;
    }
    const size_t expected = sizeof(header) + static_cast<size_t>(header.count) * sizeof(SerializedKeyPoint) +
                            static_cast<size_t>(header.count) * header.descriptor_bytes;
    if (bytes.size() != expected) return nullptr;
    auto features = std::make_shared<OrbFeatures>();
    features->size = cv::Size(header.width, header.height);
    const char* cursor = bytes.data() + sizeof(header);
    features->keypoints.resize(header.count);
    for (cv::KeyPoint& k : features->keypoints) {
      SerializedKeyPoint record;
      std::memcpy(&record, cursor, sizeof(record));
      cursor += sizeof(record);
      k = cv::KeyPoint(record.x, record.y, record.size, record.angle, record.response, record.octave);
    }
    if (header.count > 0) {
      features->binary_descriptors.create(header.count, header.descriptor_bytes, CV_8U);
      std::memcpy(features->binary_descriptors.data, cursor,
                  static_cast<size_t>(header.count) * header.descriptor_bytes);
    }
    return features;
  }

 private:
  // The pyramid's levels whose image keeps at least one pixel on a frame whose shorter side is `shorter_side`.
  int LevelsWithPixels(int shorter_side) const {
    int levels = 1;
    while (levels < options_.num_levels && shorter_side / std::pow(options_.scale_factor, levels) >= 1.0) ++levels;
    return levels;
  }

  OrbMatcherOptions options_;
  mutable std::atomic<bool> warned_levels_{false};  // said once per matcher, not once per frame
};

// The distance matrix is produced one query row at a time, into 16-bit distances padded to a multiple of
// kLanes trains, and reduced at once: per query the best and second-best train, per train the best query.
constexpr int kLanes = 16;
using Distance = uint16_t;
constexpr Distance kFar = 0x7fff;  // above any Hamming distance of descriptors under 4 KB

// Copies descriptor rows into 64-bit words (cv::Mat rows need not be aligned or contiguous), with zero rows
// up to `rows`.
std::vector<uint64_t> PackWords(const cv::Mat& descriptors, int words, int rows) {
  std::vector<uint64_t> packed(static_cast<size_t>(rows) * words, 0);
  for (int r = 0; r < descriptors.rows; ++r) {
    std::memcpy(packed.data() + static_cast<size_t>(r) * words, descriptors.ptr(r), descriptors.cols);
  }
  return packed;
}

// Any width: one popcount per 64-bit word. Compiled with the POPCNT instruction and without, picked at
// load time, so a generic x86-64 build still gets the fast path.
__attribute__((target_clones("popcnt", "default"))) void HammingRowWords(const uint64_t* query, const uint64_t* train,
                                                                         int num_train, int words,
                                                                         Distance* distances) {
  for (int j = 0; j < num_train; ++j) {
    int d = 0;
    for (int w = 0; w < words; ++w) d += __builtin_popcountll(query[w] ^ train[words * j + w]);
    distances[j] = static_cast<Distance>(d);
  }
}

#if defined(__x86_64__)
// 256-bit descriptors (ORB) with AVX2, 16 trains per step: per byte a nibble-table popcount, summed per
// 8 bytes with vpsadbw, then four trains' partial sums packed per 64-bit lane and transposed so that the
// step ends with 16 distances in one register: faster than one POPCNT per word (docs/measurements/code-choices.md,
// "ORB matching with AVX2").
// Four u64 lanes: the set bits of each 8-byte quarter of query ^ train.
__attribute__((target("avx2"))) inline __m256i QuarterCounts(__m256i query, const uint64_t* train) {
  const __m256i nibble_counts = _mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4,  //
                                                 0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4);
  const __m256i low_nibbles = _mm256_set1_epi8(0x0f);
  const __m256i x = _mm256_xor_si256(query, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(train)));
  const __m256i low = _mm256_shuffle_epi8(nibble_counts, _mm256_and_si256(x, low_nibbles));
  const __m256i high = _mm256_shuffle_epi8(nibble_counts, _mm256_and_si256(_mm256_srli_epi16(x, 4), low_nibbles));
  return _mm256_sad_epu8(_mm256_add_epi8(low, high), _mm256_setzero_si256());
}

// Lane L holds quarter L of four consecutive trains, one per 16-bit field.
__attribute__((target("avx2"))) inline __m256i FourTrains(__m256i query, const uint64_t* train) {
  return _mm256_or_si256(
      _mm256_or_si256(QuarterCounts(query, train), _mm256_slli_epi64(QuarterCounts(query, train + 4), 16)),
      _mm256_or_si256(_mm256_slli_epi64(QuarterCounts(query, train + 8), 32),
                      _mm256_slli_epi64(QuarterCounts(query, train + 12), 48)));
}

__attribute__((target("avx2"))) void HammingRow256Avx2(const uint64_t* query, const uint64_t* train, int padded_trains,
                                                       Distance* distances) {
  const __m256i q = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(query));
  for (int j = 0; j < padded_trains; j += kLanes) {
    const uint64_t* t = train + 4 * static_cast<size_t>(j);
    const __m256i a = FourTrains(q, t), b = FourTrains(q, t + 16), c = FourTrains(q, t + 32), d = FourTrains(q, t + 48);
    // Sum the four quarters: [a0+a1, b0+b1 | a2+a3, b2+b3] and the same for c, d, then across halves.
    const __m256i ab = _mm256_add_epi16(_mm256_unpacklo_epi64(a, b), _mm256_unpackhi_epi64(a, b));
    const __m256i cd = _mm256_add_epi16(_mm256_unpacklo_epi64(c, d), _mm256_unpackhi_epi64(c, d));
    const __m256i sums =
        _mm256_add_epi16(_mm256_permute2x128_si256(ab, cd, 0x20), _mm256_permute2x128_si256(ab, cd, 0x31));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(distances + j), sums);
  }
}
#endif

bool HasAvx2() {
#if defined(__x86_64__)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

struct RowBest {
  int train = -1;
  int distance = kFar;
  int second_distance = kFar;
};

// Reduces one row of distances: its best and second-best train, and the column minima (strict '<', so the
// lowest query index wins ties, as in cv::BFMatcher). Written as kLanes independent lanes so that the
// compiler vectorises it; the lanes are merged at the end.
__attribute__((target_clones("avx2", "default"))) RowBest ReduceRow(const Distance* distances, int padded_trains,
                                                                    int query, Distance* column_best,
                                                                    int* column_query) {
  Distance best[kLanes], second[kLanes];
  int arg[kLanes];
  for (int k = 0; k < kLanes; ++k) {
    best[k] = second[k] = kFar;
    arg[k] = -1;
  }
  for (int j = 0; j < padded_trains; j += kLanes) {
    for (int k = 0; k < kLanes; ++k) {
      const Distance d = distances[j + k];
      const bool row_better = d < best[k];
      second[k] = std::min(second[k], std::max(d, best[k]));
      arg[k] = row_better ? j + k : arg[k];
      best[k] = row_better ? d : best[k];
      const bool column_better = d < column_best[j + k];
      column_query[j + k] = column_better ? query : column_query[j + k];
      column_best[j + k] = column_better ? d : column_best[j + k];
    }
  }
  RowBest row;
  int winner = -1;
  for (int k = 0; k < kLanes; ++k) {  // the lowest train index among the lanes holding the minimum
    if (arg[k] < 0) continue;
    if (best[k] < row.distance || (best[k] == row.distance && arg[k] < row.train)) {
      row.distance = best[k];
      row.train = arg[k];
      winner = k;
    }
  }
  for (int k = 0; k < kLanes; ++k) {
    row.second_distance = std::min<int>(row.second_distance, k == winner ? second[k] : best[k]);
  }
  return row;
}

}  // namespace

std::vector<std::pair<int, int>> MatchBinaryDescriptors(const cv::Mat& query, const cv::Mat& train, bool cross_check,
                                                        double ratio) {
  CV_Assert(query.type() == CV_8U && train.type() == CV_8U && query.cols == train.cols && query.cols <= 4096);
  const int words = (query.cols + 7) / 8;
  const int nq = query.rows, nt = train.rows;
  const int padded = (nt + kLanes - 1) / kLanes * kLanes;
  const std::vector<uint64_t> q = PackWords(query, words, nq);
  const std::vector<uint64_t> t = PackWords(train, words, padded);
  const bool avx2 = words == 4 && HasAvx2();

  std::vector<RowBest> rows(nq);
  std::vector<Distance> column_best(padded, kFar);
  std::vector<int> column_query(padded, -1);
  std::vector<Distance> distances(padded);
  for (int i = 0; i < nq; ++i) {
    const uint64_t* row = q.data() + static_cast<size_t>(i) * words;
#if defined(__x86_64__)
    if (avx2)
      HammingRow256Avx2(row, t.data(), padded, distances.data());
    else
#endif
      HammingRowWords(row, t.data(), nt, words, distances.data());
    std::fill(distances.begin() + nt, distances.end(), kFar);  // the zero rows that pad the trains
    rows[i] = ReduceRow(distances.data(), padded, i, column_best.data(), column_query.data());
  }
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(nq);
  for (int i = 0; i < nq; ++i) {
    const RowBest& row = rows[i];
    if (row.train < 0) continue;
    if (cross_check && column_query[row.train] != i) continue;
    // With a single train there is no second distance and the ratio test does not apply.
    if (ratio > 0.0 && nt > 1 && !(row.distance < ratio * row.second_distance)) continue;
    pairs.emplace_back(i, row.train);
  }
  return pairs;
}

TentativeMatches MatchOrbInWindow(const ImageFeatures& frame, const ImageFeatures& key, const MatchWindow& window) {
  const auto& a = static_cast<const OrbFeatures&>(frame);
  const auto& b = static_cast<const OrbFeatures&>(key);
  TentativeMatches matches;
  if (a.binary_descriptors.empty() || b.binary_descriptors.empty()) return matches;
  CV_Assert(a.binary_descriptors.cols == b.binary_descriptors.cols && a.binary_descriptors.cols <= 4096);
  const int words = (a.binary_descriptors.cols + 7) / 8;
  const int na = a.binary_descriptors.rows, nb = b.binary_descriptors.rows;
  const std::vector<uint64_t> qa = PackWords(a.binary_descriptors, words, na);
  const std::vector<uint64_t> qb = PackWords(b.binary_descriptors, words, nb);
  // Per key feature: the frame feature that matched it best, and that distance.
  std::vector<int> best_query(nb, -1), best_distance(nb, kFar);
  for (int i = 0; i < na; ++i) {
    const cv::KeyPoint& p = a.keypoints[i];
    const float x = p.pt.x - static_cast<float>(window.predicted_dx), y = p.pt.y;
    const double half_width = window.half_width + window.zoom * std::abs(p.pt.x - window.centre.x);
    const double half_height = window.half_height + window.zoom * std::abs(p.pt.y - window.centre.y);
    int best = kFar, second = kFar, arg = -1;
    for (int j = 0; j < nb; ++j) {
      const cv::KeyPoint& q = b.keypoints[j];
      if (std::abs(q.pt.x - x) > half_width || std::abs(q.pt.y - y) > half_height ||
          std::abs(q.octave - p.octave) > window.max_level_difference) {
        continue;
      }
      Distance distance;  // one train row: the POPCNT-dispatched loop the full matcher uses
      HammingRowWords(qa.data() + static_cast<size_t>(i) * words, qb.data() + static_cast<size_t>(j) * words, 1, words,
                      &distance);
      const int d = distance;
      if (d < best) {
        second = best;
        best = d;
        arg = j;
      } else if (d < second) {
        second = d;
      }
    }
    if (arg < 0 || best > window.max_distance) continue;
    if (window.ratio > 0.0 && second < kFar && !(best < window.ratio * second)) continue;
    if (best < best_distance[arg]) {
      best_distance[arg] = best;
      best_query[arg] = i;
    }
  }
  for (int j = 0; j < nb; ++j) {
    if (best_query[j] < 0) continue;
    matches.points0.push_back(a.keypoints[best_query[j]].pt);
    matches.points1.push_back(b.keypoints[j].pt);
  }
  return matches;
}

std::unique_ptr<Matcher> CreateOrbMatcher(const OrbMatcherOptions& options) {
  return std::make_unique<OrbMatcher>(options);
}

}  // namespace vmap
