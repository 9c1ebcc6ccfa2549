#pragma once
// Decompressing one chunk of a recording into a buffer of the size its record announces: lz4 (LZ4's frame
// format: ROS 1's roslz4 and MCAP write it), bz2 (ROS 1) and zstd (MCAP); and rosbag2's zstd compression of
// single messages or whole database files, whose sizes nothing announces.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace vmap {

// Whether a chunk announcing `out_size` bytes once decompressed from `in_size` bytes can be believed: the
// announced size is allocated before decompressing, so a damaged field must not ask for gigabytes.
// Recorders write chunks of about 1 MB; none of them is this large, nor compressed by more than 1024:1 past it.
inline bool PlausibleChunkSize(uint64_t in_size, uint64_t out_size) {
  return out_size <= (uint64_t{256} << 20) || out_size / 1024 <= in_size;
}

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
// bytes (a damaged or hostile message must not take unbounded memory). Returns "" or what went wrong.
std::string DecompressZstd(const uint8_t* in, size_t size, size_t max_size, std::vector<uint8_t>* out);

// Decompresses the zstd file `from` into the new file `to`, streaming (memory stays flat): a database of a
// rosbag2 recorded with `--compression-mode file`. Returns "" or what went wrong.
std::string DecompressZstdFile(const std::string& from, const std::string& to);

}  // namespace vmap
