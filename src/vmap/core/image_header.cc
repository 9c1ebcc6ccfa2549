#include "vmap/core/image_header.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>

namespace vmap {

namespace {

// Reads `bytes` bytes at `offset`; false when the file or buffer ends before them.
using ReadBytes = std::function<bool(std::uint64_t offset, void* data, std::size_t bytes)>;

// The width and height a PNG file's header announces, or nullopt when the file is not a PNG.
std::optional<cv::Size> PngSize(const ReadBytes& read) {
  unsigned char header[24];
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (!read(0, header, sizeof(header)) || std::memcmp(header, kSignature, 8) != 0 ||
      std::memcmp(header + 12, "IHDR", 4) != 0) {
    return std::nullopt;
  }
  auto big_endian = [&](int at) {
    return (std::uint32_t(header[at]) << 24) | (std::uint32_t(header[at + 1]) << 16) |
           (std::uint32_t(header[at + 2]) << 8) | std::uint32_t(header[at + 3]);
  };
  const std::uint32_t width = big_endian(16), height = big_endian(20);
  if (width > (1u << 20) || height > (1u << 20)) return cv::Size(1 << 20, 1 << 20);
  return cv::Size(static_cast<int>(width), static_cast<int>(height));
}

// The width and height of a baseline or progressive JPEG file's frame header (SOFn), or nullopt when the file
// is not a JPEG. Walks the marker segments from the start; at most 64 segments and 1 MiB are looked at, since
// the frame header comes before any image data.
std::optional<cv::Size> JpegSize(const ReadBytes& read) {
  unsigned char bytes[9];
  if (!read(0, bytes, 2) || bytes[0] != 0xFF || bytes[1] != 0xD8) return std::nullopt;
  std::uint64_t at = 2;
  for (int segment = 0; segment < 64 && at < (1u << 20); ++segment) {
    if (!read(at, bytes, 4) || bytes[0] != 0xFF) return std::nullopt;
    const int marker = bytes[1];
    const int length = (bytes[2] << 8) | bytes[3];
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC): precision, height, width.
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
      if (!read(at + 4, bytes, 5)) return std::nullopt;
      return cv::Size((bytes[3] << 8) | bytes[4], (bytes[1] << 8) | bytes[2]);
    }
    if (marker == 0xD9 || marker == 0xDA || length < 2) return std::nullopt;  // end or scan before a frame
    at += 2 + static_cast<std::uint64_t>(length);
  }
  return std::nullopt;
}

std::optional<cv::Size> HeaderSize(const ReadBytes& read) {
  if (auto size = PngSize(read)) return size;
  return JpegSize(read);
}

// Whether `size` bytes start as a JPEG and their last 64 KiB hold no end-of-image marker.
bool CutShortJpeg(const ReadBytes& read, std::uint64_t size) {
  unsigned char start[2] = {};
  if (size < 4 || !read(0, start, 2) || start[0] != 0xFF || start[1] != 0xD8) return false;
  const std::uint64_t window = std::min<std::uint64_t>(size - 2, std::uint64_t{64} << 10);
  std::string tail(window, '\0');
  if (!read(size - window, tail.data(), tail.size())) return false;
  for (size_t i = tail.size() - 1; i > 0; --i) {
    if (static_cast<unsigned char>(tail[i - 1]) == 0xFF && static_cast<unsigned char>(tail[i]) == 0xD9) return false;
  }
  return true;
}

// Whether `size` bytes start as a PNG and their last 64 KiB hold no IEND chunk (its type and fixed CRC, AE 42 60 82).
bool CutShortPng(const ReadBytes& read, std::uint64_t size) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  static const std::string kEnd = {'I', 'E', 'N', 'D', '\xAE', '\x42', '\x60', '\x82'};
  unsigned char start[8] = {};
  if (size < 8 || !read(0, start, 8) || std::memcmp(start, kSignature, 8) != 0) return false;
  const std::uint64_t window = std::min<std::uint64_t>(size - 8, std::uint64_t{64} << 10);
  std::string tail(window, '\0');
  if (!read(size - window, tail.data(), tail.size())) return false;
  return tail.find(kEnd) == std::string::npos;
}

const char* CutShort(const ReadBytes& read, std::uint64_t size) {
  if (CutShortJpeg(read, size)) return "a JPEG cut short (no end-of-image marker)";
  if (CutShortPng(read, size)) return "a PNG cut short (no IEND chunk)";
  return nullptr;
}

// The reader of an open file.
ReadBytes FromFile(const ContainedFile& file) {
  return [&file](std::uint64_t offset, void* data, std::size_t bytes) { return file.Read(offset, data, bytes); };
}

// The reader of an encoded image held in memory.
ReadBytes InMemory(const std::uint8_t* encoded, std::size_t size) {
  return [encoded, size](std::uint64_t offset, void* data, std::size_t bytes) {
    if (offset > size || bytes > size - offset) return false;
    std::memcpy(data, encoded + offset, bytes);
    return true;
  };
}

}  // namespace

std::optional<cv::Size> ImageHeaderSize(const ContainedFile& file) { return HeaderSize(FromFile(file)); }

const char* CutShortImage(const ContainedFile& file) { return CutShort(FromFile(file), file.size()); }

const char* CutShortImage(const std::uint8_t* encoded, std::size_t size) {
  return CutShort(InMemory(encoded, size), size);
}

std::optional<cv::Size> ImageHeaderSize(const std::uint8_t* encoded, std::size_t size) {
  return HeaderSize(InMemory(encoded, size));
}

}  // namespace vmap
