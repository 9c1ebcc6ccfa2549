#include "vmap/core/image_decode.h"

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/core/image_header.h"

namespace vmap {

cv::Mat DecodeImageFile(const ContainedFile& file, int flags, long max_pixels, std::string* why_not) {
  if (file.size() > kMaxImageFileBytes) {
    *why_not = fmt::format("is {} bytes, more than any image file vmap reads (1 GiB)", file.size());
    return {};
  }
  std::string bytes;
  if (!file.ReadAll(&bytes)) {
    *why_not = "cannot be read (it changed while it was read?)";
    return {};
  }
  const auto* encoded = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (const std::optional<cv::Size> announced = ImageHeaderSize(encoded, bytes.size());
      announced && static_cast<long>(announced->width) * announced->height > max_pixels) {
    *why_not = fmt::format("announces {}x{} in its header, more than {} pixels", announced->width, announced->height,
                           max_pixels);
    return {};
  }
  // After the announced size: a header alone (a decompression bomb) is cut short too, and its size says more.
  if (const char* cut = CutShortImage(encoded, bytes.size())) {
    *why_not = std::string("is ") + cut;
    return {};
  }
  cv::Mat image;
  try {
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, bytes.data()), flags);
  } catch (const cv::Exception& error) {
    // OpenCV refuses some files outright, e.g. a header announcing more than 2^30 pixels.
    *why_not = "cannot be decoded (" + LibraryMessage(error) + ")";
    return {};
  }
  if (image.empty()) *why_not = "cannot be decoded (corrupt or not an image)";
  return image;
}

}  // namespace vmap
