#pragma once
// The matcher interface. Features of an image are computed once (Extract) and reused for every pair the
// image takes part in: the current key image is never re-extracted for each new frame.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

// Whatever a matcher computes per image (ORB keypoints and descriptors, LoFTR backbone features...).
class ImageFeatures {
 public:
  virtual ~ImageFeatures() = default;
  // |D| of the paper for the literal "feature-ratio" similarity: the features detected in this image.
  virtual int num_features() const = 0;
  // The size of the image the features were extracted from (coordinates refer to it).
  virtual cv::Size image_size() const = 0;
  // Optional: one descriptor row per feature, for ranking key images by shared descriptors (vmap localize).
  // CV_8U rows are binary descriptors compared by Hamming distance (ORB); CV_32F rows are L2-normalised
  // descriptors compared by dot product (XFeat, ALIKED). Empty for a matcher without per-feature
  // descriptors (LoFTR): localization then ranks key images by their downsampled pixels instead.
  virtual cv::Mat descriptors() const { return {}; }
};

// Tentative correspondences between two images, in pixel coordinates of the images given to Extract
// (OpenCV convention: pixel centres at integer coordinates).
struct TentativeMatches {
  std::vector<cv::Point2f> points0;
  std::vector<cv::Point2f> points1;
  std::vector<float> scores;  // matcher confidence per match (higher is better); may be empty
  size_t size() const { return points0.size(); }
};

class Matcher {
 public:
  virtual ~Matcher() = default;
  virtual std::string name() const = 0;
  // `gray` is 8-bit single-channel. Never returns null; an image without features gives num_features() == 0.
  virtual std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const = 0;
  // A model whose upstream reads colour says so (XFeat averages B, G, R, which no grey conversion of the
  // decoder or of cvtColor equals): its callers then give ExtractFrame the frame's colour image too.
  virtual bool reads_color() const { return false; }
  // `bgr` is the same image as `gray`, 8-bit BGR, or empty for a grey input. The default, for matchers that
  // read grey, ignores it, so that their features do not depend on whether the input had colour.
  virtual std::shared_ptr<const ImageFeatures> ExtractFrame(const cv::Mat& gray, const cv::Mat& bgr) const {
    return Extract(gray);
  }
  // Features only where `keep` (CV_8UC1, the image's size) is non-zero: within a camera mask
  // (features/camera_mask.h, which calls it). Null when the matcher cannot leave features out (LoFTR's are dense):
  // its matches are then filtered instead.
  virtual std::shared_ptr<const ImageFeatures> ExtractFrameWithin(const cv::Mat& gray, const cv::Mat& bgr,
                                                                  const cv::Mat& keep) const {
    return nullptr;
  }
  // Features must come from this matcher's Extract.
  virtual TentativeMatches Match(const ImageFeatures& features0, const ImageFeatures& features1) const = 0;
  // The matcher's settings, recorded in map.json.
  virtual std::string DescribeOptionsJson() const = 0;
  // Optional: features as bytes and back, so that vmap localize extracts a map's key images once and keeps
  // them in a cache. Bytes are read back only by the same matcher with the same options (the cache checks).
  // A matcher that cannot do it returns "" and null; its key images are then extracted at every start.
  virtual std::string SerializeFeatures(const ImageFeatures& features) const { return {}; }
  virtual std::shared_ptr<const ImageFeatures> DeserializeFeatures(std::string_view bytes) const { return nullptr; }
};

}  // namespace vmap
