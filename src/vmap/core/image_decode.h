#pragma once
// Images decoded from a file's bytes read once, through the file that was opened and checked: decoding by path again
// (cv::imread) would decode whatever is there by then (a file the recorder replaced, a FIFO that blocks the decoder),
// not what was checked.

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/contained_file.h"

namespace vmap {

// No image file vmap reads is larger: an uncompressed 16-bit RGBA PNG of the largest frame (8192 x 8192) takes 512 MiB.
inline constexpr std::uint64_t kMaxImageFileBytes = std::uint64_t{1} << 30;

// The image in `file`, decoded with OpenCV's imread `flags` (cv::IMREAD_GRAYSCALE, cv::IMREAD_COLOR, ...) from its
// bytes. Empty, with `*why_not` saying why ("is a JPEG cut short (no end-of-image marker)", "cannot be decoded
// (...)"), when the file is larger than kMaxImageFileBytes or cannot be read, is a JPEG cut short (libjpeg would decode
// it with its missing rows grey), announces more than `max_pixels` in its header (before anything is allocated for
// it), or does not decode.
cv::Mat DecodeImageFile(const ContainedFile& file, int flags, long max_pixels, std::string* why_not);

}  // namespace vmap
