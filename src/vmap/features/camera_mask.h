#pragma once
// A camera mask: the pixels where no feature may be found, whatever the scene (COLMAP's camera mask, the same
// convention: an 8-bit image of the frames' size, black = no features there). What it is for: a fisheye's dark
// rim and lens ring, or the robot's own body in view, match themselves at the same pixels in every pair of images
// and so let any two places verify ("The lens rim's matches", docs/measurements/localization-conditions.md).
//
// A matcher given a mask (WithCameraMask; `vmap build --camera-mask`) extracts features only where the mask is
// non-zero; a map records the mask it was built with (camera_mask.png beside map.json) and localization extracts
// the frames and the key images within it.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/features/matcher.h"

namespace vmap {

class CameraMask {
 public:
  // Reads an image file (any format OpenCV reads; colour is read as grey). Throws InputError naming the file when
  // it cannot be read or masks every pixel.
  static CameraMask Read(const std::filesystem::path& file);
  // `image`: CV_8UC1, 0 where no features may be; any other value keeps the pixel. `source` names it in messages.
  // Throws InputError as Read does.
  CameraMask(const cv::Mat& image, std::string source);

  const cv::Mat& image() const { return image_; }  // 0 or 255
  const std::string& source() const { return source_; }
  double kept_share() const { return kept_share_; }  // of the pixels, those where features may be
  // "<width>x<height> <kept %> <FNV-1a of the pixels>": what a matcher's record says of its mask, so that a
  // cache of features extracted within another mask is not read back.
  std::string Describe() const;

  // The mask for images of `size`: itself, or resized (nearest pixel) to a size of its aspect ratio (each side
  // within a pixel of the scaled one), as frames given --resize are. Throws InputError naming the source for
  // another aspect ratio.
  cv::Mat For(cv::Size size) const;

 private:
  cv::Mat image_;
  std::string source_;
  double kept_share_ = 0.0;
};

// Whether `point` (pixel centres at integer coordinates) lies where `keep` (For's result) is non-zero; a point
// outside the image is not kept.
bool KeptByMask(const cv::Mat& keep, cv::Point2f point);
// The indices of `points` that `keep` keeps, in order.
std::vector<int> KeptPointIndices(const cv::Mat& keep, const std::vector<cv::Point2f>& points);

// `matcher` extracting features only where `mask` keeps pixels (Matcher::ExtractFrameWithin; a matcher that cannot
// leave features out, LoFTR, has its matches with an end outside the mask dropped instead). Its name and
// reads_color are `matcher`'s; its record (DescribeOptionsJson) is `matcher`'s with "camera_mask": Describe().
std::unique_ptr<Matcher> WithCameraMask(std::unique_ptr<Matcher> matcher, CameraMask mask);
// The mask `matcher` extracts within (WithCameraMask), or null.
const CameraMask* CameraMaskOf(const Matcher& matcher);
// `matcher` within the same mask as `like`, when `like` has one; `matcher` itself otherwise.
std::unique_ptr<Matcher> WithCameraMaskOf(const Matcher& like, std::unique_ptr<Matcher> matcher);

}  // namespace vmap
