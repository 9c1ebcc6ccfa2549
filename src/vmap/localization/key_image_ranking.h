#pragma once
// Ranking every key image of a map against a query image, cheaply, before the few best are verified
// geometrically (relocalization).
//
// Two rankings, chosen by what the matcher gives:
//  - descriptor votes: a few hundred of the query's per-feature descriptors are matched by brute force with
//    a few hundred of every key image's (mutual nearest neighbours: Hamming for binary descriptors, dot
//    product for float ones); a key image scores the matches that are close enough. Needs
//    ImageFeatures::descriptors() (ORB, and the deep detectors XFeat and ALIKED).
//  - thumbnails: each image shrunk to a few hundred pixels, normalised for brightness and contrast, and
//    compared by correlation. Needs only the pixels, so it serves matchers without per-feature descriptors
//    (LoFTR).

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/core/option_fields.h"
#include "vmap/features/matcher.h"

namespace vmap {

enum class RankingMethod {
  kAuto,        // descriptor votes when the matcher has per-feature descriptors, thumbnails otherwise
  kVotes,       // descriptor votes (fails for a matcher without descriptors)
  kThumbnails,  // downsampled-image correlation
};
inline constexpr EnumName<RankingMethod> kRankingMethodNames[] = {
    {RankingMethod::kAuto, "auto"}, {RankingMethod::kVotes, "votes"}, {RankingMethod::kThumbnails, "thumbnails"}};
RankingMethod ParseRankingMethod(const std::string& name);
std::string RankingMethodName(RankingMethod method);

struct RankingOptions {
  RankingMethod method = RankingMethod::kAuto;
  // Descriptor votes. A binary match counts when its Hamming distance is at most this fraction of the
  // descriptor's bits (0.25 = 64 of ORB's 256 bits, where ORB matches of one scene point usually lie).
  double max_hamming_fraction = 0.25;
  // A float match (unit descriptors) counts when the dot product is at least this.
  double min_cosine = 0.8;
  // At most this many descriptors of the query and of each key image take part, evenly spread over the
  // matcher's list: bounds the time (it grows with their product and the number of key images) and the
  // memory for deep detectors with thousands of keypoints per image. 0 = all.
  int max_descriptors_per_key = 250;
  // Thumbnails: width in pixels (height keeps the aspect ratio, at least 8).
  int thumbnail_width = 48;

  // As a localization run records them ("options.ranking"); only the method has a flag (--ranking).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// The thumbnail descriptor of a grey image: shrunk to `width` (INTER_AREA), zero mean, unit norm, as CV_32F
// row. Correlation of two thumbnails is their dot product.
cv::Mat ThumbnailDescriptor(const cv::Mat& gray, int width);

struct RankedKey {
  int key = -1;        // index of the key image in the map
  double score = 0.0;  // votes (descriptor votes) or correlation in [-1, 1] (thumbnails); higher is better
};

// The ranking of one map's key images, built once (the index holds every key image) and queried per frame.
class KeyImageRanking {
 public:
  // `key_features[k]` and `key_thumbnails[k]` (ThumbnailDescriptor) belong to key image k. Resolves kAuto
  // from the first key image's descriptors. Throws InputError for kVotes without descriptors.
  KeyImageRanking(const std::vector<std::shared_ptr<const ImageFeatures>>& key_features,
                  std::vector<cv::Mat> key_thumbnails, const RankingOptions& options);
  ~KeyImageRanking();
  KeyImageRanking(const KeyImageRanking&) = delete;
  KeyImageRanking& operator=(const KeyImageRanking&) = delete;

  // The method in use (never kAuto).
  RankingMethod method() const { return method_; }

  // Every key image, best first (ties by key index). `thumbnail` is the query's ThumbnailDescriptor (needed
  // only by the thumbnail ranking), `features` the query's features from the map's matcher.
  std::vector<RankedKey> Rank(const ImageFeatures& features, const cv::Mat& thumbnail) const;

 private:
  class VoteIndex;
  RankingOptions options_;
  RankingMethod method_ = RankingMethod::kThumbnails;
  int num_keys_ = 0;
  std::unique_ptr<VoteIndex> votes_;
  cv::Mat thumbnails_;  // one row per key image
};

}  // namespace vmap
