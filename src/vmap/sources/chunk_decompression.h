#pragma once
// Decompressing one chunk of a recording into a buffer of the size its record announces (checked first
// against recording_limits.h): lz4 (LZ4's frame
// format: ROS 1's roslz4 and MCAP write it), bz2 (ROS 1) and zstd (MCAP); and rosbag2's zstd compression of
// single messages or whole database files, whose sizes nothing announces.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "vmap/core/contained_file.h"

namespace vmap {

// Decompresses `size` bytes at `in` with `compression` ("lz4", "bz2" or "zstd") into exactly `out_size`
// bytes at `out`. Returns "" on success, or what went wrong (an unknown compression, damaged data, a size
// that differs from the announced one).
std::string DecompressChunk(const std::string& compression, const uint8_t* in, size_t size, uint8_t* out,
                            size_t out_size);

// Whether `data` starts a zstd frame: how a message of a rosbag2 recorded with `--compression-mode message` is
// told from a plain one. A CDR message starts with its encapsulation header, whose first byte is 0, so the
// two cannot be confused.
bool StartsWithZstdFrame(const uint8_t* data, size_t size);

// Decompresses the zstd frame(s) of `size` bytes at `in` into `out`, refusing to produce more than `max_size`
// bytes (a damaged or hostile message must not take unbounded memory). Returns "" or what went wrong;
// `*too_large` (when given) says whether it was the size.
std::string DecompressZstd(const uint8_t* in, size_t size, size_t max_size, std::vector<uint8_t>* out,
                           bool* too_large = nullptr);

// Decompresses the zstd file `in` (already open: a regular file) into the new file `to`, streaming (memory
// stays flat), refusing to write more than `max_size` bytes: a database of a rosbag2 recorded with
// `--compression-mode file`. Returns "" or what went wrong.
std::string DecompressZstdFile(const ContainedFile& in, const std::string& to, uint64_t max_size);

}  // namespace vmap
