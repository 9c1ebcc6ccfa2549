#pragma once
// An image's size as its file's header announces it, read without decoding anything: so that a small file
// announcing 32000 x 32000 pixels is refused before a decoder allocates a gigabyte for it. OpenCV has such a
// limit too (OPENCV_IO_MAX_IMAGE_PIXELS), but reads it once when the library loads, and at 2^30 pixels.

#include <cstddef>
#include <cstdint>
#include <optional>

#include <opencv2/core.hpp>

#include "vmap/core/contained_file.h"

namespace vmap {

// The width and height of a PNG (IHDR) or a baseline or progressive JPEG (SOFn), or nullopt when the file is
// neither (or is cut short): then only the decoder's own checks apply. Sides beyond 2^20 are returned as 2^20.
std::optional<cv::Size> ImageHeaderSize(const ContainedFile& file);
// The same of an encoded image held in memory (a ROS CompressedImage message's data).
std::optional<cv::Size> ImageHeaderSize(const std::uint8_t* encoded, std::size_t size);

// What the file is when it is an image cut short (as a full disk or a recording cut off leaves one), or nullptr: a JPEG
// whose last 64 KiB hold no end-of-image marker (FF D9, which the entropy-coded data never holds: a 0xFF there is
// followed by 0x00 or a restart marker), which libjpeg decodes without an error, its missing rows filled grey and then
// matched as if seen; a PNG whose last 64 KiB hold no IEND chunk, which a header check alone would take for whole.
const char* CutShortImage(const ContainedFile& file);
// The same of an encoded image held in memory (the bytes about to be decoded).
const char* CutShortImage(const std::uint8_t* encoded, std::size_t size);

}  // namespace vmap
