#include "vmap/localization/key_image_ranking.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"
#include "vmap/features/float_matcher.h"
#include "vmap/features/orb_matcher.h"

namespace vmap {

RankingMethod ParseRankingMethod(const std::string& name) { return ParseEnum(kRankingMethodNames, name, "ranking"); }

std::string RankingMethodName(RankingMethod method) { return EnumToName(kRankingMethodNames, method); }

void RankingOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"method", "--ranking", "Relocalization ranking: "}.ListingNames(),
                EnumField(method, kRankingMethodNames, ParseRankingMethod));
  visitor.Visit(OptionField{"max_hamming_fraction"}.Within(0, 0.5).ExcludingMin(), max_hamming_fraction);
  visitor.Visit(OptionField{"min_cosine"}.Within(-1, 1).ExcludingMin().ExcludingMax(), min_cosine);
  visitor.Visit(OptionField{"max_descriptors_per_key"}.Within(0, 100000).Meaning("0: all"), max_descriptors_per_key);
  visitor.Visit(OptionField{"thumbnail_width"}.Within(8, 512), thumbnail_width);
}

void RankingOptions::Check() const { CheckFieldRanges(*this); }

cv::Mat ThumbnailDescriptor(const cv::Mat& gray, int width) {
  CV_Assert(!gray.empty() && gray.type() == CV_8UC1);
  const int height = std::max(8, static_cast<int>(std::lround(static_cast<double>(width) * gray.rows / gray.cols)));
  cv::Mat small;
  cv::resize(gray, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  cv::Mat row;
  small.reshape(1, 1).convertTo(row, CV_32F);
  row -= cv::mean(row)[0];
  const double norm = cv::norm(row);
  if (norm > 1e-6) row /= norm;  // a flat image stays zero: it correlates with nothing
  return row;
}

namespace {

// At most `count` rows, evenly spread: detectors list their features level by level or by score, so the
// first rows alone would all come from one pyramid level.
cv::Mat SpreadRows(const cv::Mat& descriptors, int count) {
  if (count <= 0 || descriptors.rows <= count) return descriptors;
  cv::Mat rows(count, descriptors.cols, descriptors.type());
  for (int i = 0; i < count; ++i) {
    descriptors.row(static_cast<int>(static_cast<long>(i) * descriptors.rows / count)).copyTo(rows.row(i));
  }
  return rows;
}

int HammingDistance(const uchar* a, const uchar* b, int bytes) {
  int distance = 0;
  for (int i = 0; i < bytes; ++i) distance += __builtin_popcount(static_cast<unsigned>(a[i] ^ b[i]));
  return distance;
}

}  // namespace

// Each key image's descriptors (at most max_descriptors_per_key); a query is matched with every key image by
// brute force, cross-checked, and a key image's score is the number of matches that are close enough.
// Why brute force and not an approximate index: OpenCV's FLANN multi-probe LSH, the packaged index for binary
// descriptors, took far longer per query than this on an ORB map (docs/measurements/code-choices.md, "Ranking
// key images by brute force"; ORB's bits are far from uniform, so its hash buckets are very unequal), and brute
// force over a few hundred descriptors per key image stays within the relocalization budget for a few hundred
// key images.
class KeyImageRanking::VoteIndex {
 public:
  VoteIndex(const std::vector<std::shared_ptr<const ImageFeatures>>& key_features, const RankingOptions& options)
      : options_(options) {
    for (const auto& features : key_features) {
      cv::Mat d = features ? SpreadRows(features->descriptors(), options.max_descriptors_per_key) : cv::Mat();
      if (!d.empty()) {
        if (type_ < 0) type_ = d.type(), cols_ = d.cols;
        if (d.type() != type_ || d.cols != cols_) {
          throw InputError("key images have descriptors of different kinds; rebuild the map");
        }
        if (type_ != CV_8U && type_ != CV_32F) d.convertTo(d, CV_32F);
      }
      keys_.push_back(d);
    }
    if (type_ != CV_8U) type_ = CV_32F;
  }

  void Vote(const cv::Mat& query_descriptors, std::vector<double>& votes) const {
    if (query_descriptors.empty() || query_descriptors.cols != cols_) return;
    cv::Mat query = SpreadRows(query_descriptors, options_.max_descriptors_per_key);
    if (type_ == CV_8U) {
      if (query.type() != CV_8U) return;
      const int max_distance = static_cast<int>(options_.max_hamming_fraction * cols_ * 8);
      for (size_t k = 0; k < keys_.size(); ++k) {
        if (keys_[k].empty()) continue;
        for (const auto& [i, j] : MatchBinaryDescriptors(query, keys_[k], true, 0.0)) {
          if (HammingDistance(query.ptr(i), keys_[k].ptr(j), cols_) <= max_distance) votes[k] += 1.0;
        }
      }
    } else {
      if (query.type() != CV_32F) query.convertTo(query, CV_32F);
      for (size_t k = 0; k < keys_.size(); ++k) {
        if (keys_[k].empty()) continue;
        votes[k] +=
            static_cast<double>(MatchFloatDescriptors(query, keys_[k], static_cast<float>(options_.min_cosine)).size());
      }
    }
  }

 private:
  RankingOptions options_;
  int type_ = -1;
  int cols_ = 0;
  std::vector<cv::Mat> keys_;
};

KeyImageRanking::KeyImageRanking(const std::vector<std::shared_ptr<const ImageFeatures>>& key_features,
                                 std::vector<cv::Mat> key_thumbnails, const RankingOptions& options)
    : options_(options), num_keys_(static_cast<int>(key_features.size())) {
  options_.Check();
  CV_Assert(key_thumbnails.size() == key_features.size());
  const bool has_descriptors = std::any_of(key_features.begin(), key_features.end(),
                                           [](const auto& f) { return f && !f->descriptors().empty(); });
  method_ = options_.method;
  if (method_ == RankingMethod::kAuto) method_ = has_descriptors ? RankingMethod::kVotes : RankingMethod::kThumbnails;
  if (method_ == RankingMethod::kVotes) {
    if (!has_descriptors) {
      throw InputError(
          "ranking by descriptor votes needs a matcher with per-feature descriptors; this map's "
          "matcher has none: use the thumbnail ranking");
    }
    votes_ = std::make_unique<VoteIndex>(key_features, options_);
  } else if (!key_thumbnails.empty()) {
    cv::vconcat(key_thumbnails, thumbnails_);
  }
}

KeyImageRanking::~KeyImageRanking() = default;

std::vector<RankedKey> KeyImageRanking::Rank(const ImageFeatures& features, const cv::Mat& thumbnail) const {
  std::vector<double> scores(num_keys_, 0.0);
  if (method_ == RankingMethod::kVotes) {
    votes_->Vote(features.descriptors(), scores);
  } else if (!thumbnails_.empty() && !thumbnail.empty() && thumbnail.cols == thumbnails_.cols) {
    cv::Mat correlations = thumbnails_ * thumbnail.t();
    for (int k = 0; k < num_keys_; ++k) scores[k] = correlations.at<float>(k, 0);
  }
  std::vector<RankedKey> ranked(num_keys_);
  for (int k = 0; k < num_keys_; ++k) ranked[k] = {k, scores[k]};
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const RankedKey& a, const RankedKey& b) { return a.score > b.score; });
  return ranked;
}

}  // namespace vmap
