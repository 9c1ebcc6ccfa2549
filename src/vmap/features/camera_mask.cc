#include "vmap/features/camera_mask.h"

#include <cmath>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/fnv1a.h"
#include "vmap/core/image_decode.h"

namespace vmap {

CameraMask CameraMask::Read(const std::filesystem::path& file) {
  const std::string fix = "give an image of the frames' size, black where no features may be";
  std::string why_not;
  const std::optional<ContainedFile> opened = ContainedFile::OpenRegular(file, &why_not);
  if (!opened) throw InputError(fmt::format("camera mask '{}' {}: {}", file.string(), why_not, fix));
  // A frame has at most 8192 x 8192 pixels (sources/frame_source.h); a larger mask is refused before decoding.
  const cv::Mat image = DecodeImageFile(*opened, cv::IMREAD_GRAYSCALE, 8192L * 8192L, &why_not);
  if (image.empty()) throw InputError(fmt::format("camera mask '{}' {}: {}", file.string(), why_not, fix));
  return CameraMask(image, "camera mask '" + file.string() + "'");
}

CameraMask::CameraMask(const cv::Mat& image, std::string source) : source_(std::move(source)) {
  if (image.empty() || image.type() != CV_8UC1) {
    throw InputError(source_ + " is not an 8-bit single-channel image");
  }
  image_ = image != 0;  // 255 where kept
  const int kept = cv::countNonZero(image_);
  if (kept == 0) {
    throw InputError(source_ + " is black everywhere: no feature could be found; black marks where none may be");
  }
  kept_share_ = double(kept) / double(image_.total());
}

std::string CameraMask::Describe() const {
  // The pixels row by row (a row of a cv::Mat may be followed by padding).
  uint64_t hash = kFnv1aOffsetBasis;
  for (int r = 0; r < image_.rows; ++r) {
    hash = Fnv1a(std::string_view(image_.ptr<char>(r), static_cast<size_t>(image_.cols)), hash);
  }
  return fmt::format("{}x{} {:.1f}% {:016x}", image_.cols, image_.rows, 100.0 * kept_share_, hash);
}

cv::Mat CameraMask::For(cv::Size size) const {
  if (size == image_.size()) return image_;
  const double scale_x = double(size.width) / image_.cols, scale_y = double(size.height) / image_.rows;
  // The sizes --resize gives keep the aspect ratio to a rounded pixel.
  const bool same_aspect =
      std::abs(image_.cols * scale_y - size.width) <= 1.0 || std::abs(image_.rows * scale_x - size.height) <= 1.0;
  if (!same_aspect || size.empty()) {
    throw InputError(
        fmt::format("{} is {}x{}, the images are {}x{}: give a mask of the images' size (or of their "
                    "aspect ratio)",
                    source_, image_.cols, image_.rows, size.width, size.height));
  }
  cv::Mat resized;
  cv::resize(image_, resized, size, 0, 0, cv::INTER_NEAREST);
  return resized;
}

bool KeptByMask(const cv::Mat& keep, cv::Point2f point) {
  const int x = cvRound(point.x), y = cvRound(point.y);
  return x >= 0 && y >= 0 && x < keep.cols && y < keep.rows && keep.at<uchar>(y, x) != 0;
}

std::vector<int> KeptPointIndices(const cv::Mat& keep, const std::vector<cv::Point2f>& points) {
  std::vector<int> kept;
  kept.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (KeptByMask(keep, points[i])) kept.push_back(static_cast<int>(i));
  }
  return kept;
}

namespace {

class CameraMaskedMatcher : public Matcher {
 public:
  CameraMaskedMatcher(std::unique_ptr<Matcher> matcher, CameraMask mask)
      : matcher_(std::move(matcher)), mask_(std::move(mask)) {}

  const CameraMask& mask() const { return mask_; }

  std::string name() const override { return matcher_->name(); }
  bool reads_color() const override { return matcher_->reads_color(); }

  std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const override { return ExtractFrame(gray, {}); }

  std::shared_ptr<const ImageFeatures> ExtractFrame(const cv::Mat& gray, const cv::Mat& bgr) const override {
    return ExtractFrameWithin(gray, bgr, cv::Mat());
  }

  std::shared_ptr<const ImageFeatures> ExtractFrameWithin(const cv::Mat& gray, const cv::Mat& bgr,
                                                          const cv::Mat& keep) const override {
    cv::Mat within = mask_.For(gray.size());  // may be the mask itself: never written to
    if (!keep.empty()) {
      cv::Mat both;
      cv::bitwise_and(within, keep, both);
      within = both;
    }
    std::shared_ptr<const ImageFeatures> features = matcher_->ExtractFrameWithin(gray, bgr, within);
    // A matcher that cannot leave features out has its matches filtered (Match).
    return features ? features : matcher_->ExtractFrame(gray, bgr);
  }

  // Every match with an end outside the mask is dropped: none for a matcher that extracted within it, but a
  // keypoint found at a coarse pyramid level may round to a pixel beside the mask's edge, and LoFTR extracts
  // everywhere.
  TentativeMatches Match(const ImageFeatures& features0, const ImageFeatures& features1) const override {
    TentativeMatches all = matcher_->Match(features0, features1);
    const cv::Mat keep0 = mask_.For(features0.image_size()), keep1 = mask_.For(features1.image_size());
    TentativeMatches kept;
    kept.points0.reserve(all.size());
    kept.points1.reserve(all.size());
    for (size_t i = 0; i < all.size(); ++i) {
      if (!KeptByMask(keep0, all.points0[i]) || !KeptByMask(keep1, all.points1[i])) continue;
      kept.points0.push_back(all.points0[i]);
      kept.points1.push_back(all.points1[i]);
      if (!all.scores.empty()) kept.scores.push_back(all.scores[i]);
    }
    return kept;
  }

  std::string DescribeOptionsJson() const override {
    nlohmann::json record = nlohmann::json::parse(matcher_->DescribeOptionsJson());
    record["camera_mask"] = mask_.Describe();
    return record.dump();
  }
  std::string SerializeFeatures(const ImageFeatures& features) const override {
    return matcher_->SerializeFeatures(features);
  }
  std::shared_ptr<const ImageFeatures> DeserializeFeatures(std::string_view bytes) const override {
    return matcher_->DeserializeFeatures(bytes);
  }

 private:
  std::unique_ptr<Matcher> matcher_;
  CameraMask mask_;
};

}  // namespace

std::unique_ptr<Matcher> WithCameraMask(std::unique_ptr<Matcher> matcher, CameraMask mask) {
  return std::make_unique<CameraMaskedMatcher>(std::move(matcher), std::move(mask));
}

const CameraMask* CameraMaskOf(const Matcher& matcher) {
  const auto* masked = dynamic_cast<const CameraMaskedMatcher*>(&matcher);
  return masked ? &masked->mask() : nullptr;
}

std::unique_ptr<Matcher> WithCameraMaskOf(const Matcher& like, std::unique_ptr<Matcher> matcher) {
  const CameraMask* mask = CameraMaskOf(like);
  return mask ? WithCameraMask(std::move(matcher), *mask) : std::move(matcher);
}

}  // namespace vmap
