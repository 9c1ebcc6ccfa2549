#pragma once
// Decompressing one chunk of a recording into a buffer of the size its record announces: lz4 (LZ4's frame
// format: ROS 1's roslz4 and MCAP write it), bz2 (ROS 1) and zstd (MCAP).

#include <cstddef>
#include <cstdint>
#include <string>

namespace vmap {

// Decompresses `size` bytes at `in` with `compression` ("lz4", "bz2" or "zstd") into exactly `out_size`
// bytes at `out`. Returns "" on success, or what went wrong (an unknown compression, damaged data, a size
// that differs from the announced one).
std::string DecompressChunk(const std::string& compression, const uint8_t* in, size_t size, uint8_t* out,
                            size_t out_size);

}  // namespace vmap
