#pragma once
// Recordings built byte by byte for the tests of hostile input (sources/recording_limits.h): a ROS 1 bag
// written natively (no python3-rosbag, and with fields a recorder would never write: chunks that announce
// more than they hold, chunks of zeros), and the compressors the containers use.

#include <cstdint>
#include <string>
#include <vector>

#include "vmap/testing/recording_writer.h"

namespace vmap::testing {

// One chunk of a ROS 1 bag: the connection and message records of `messages`, compressed with `compression`
// ("none", "bz2" or "lz4"). `announced_size` (when not 0) replaces the decompressed size its header gives;
// `padding`: then a message on /padding of that many zero bytes (a chunk that decompresses to much more than
// it holds; the zeros are never held).
struct Ros1Chunk {
  std::vector<TestMessage> messages;
  std::string compression = "none";
  uint64_t announced_size = 0;
  uint64_t padding = 0;
  std::string stored;  // when not empty: the chunk's data as stored (compressed), instead of the above
};

// A ROS 1 bag (format 2.0) of these chunks, without an index (as a bag still being recorded).
std::string Ros1BagBytes(const std::vector<Ros1Chunk>& chunks);
// The connection and message records a chunk of `messages` holds (connection ids from 1), then the record of
// a /padding message of `padding` bytes but for those bytes (zeros, for CompressedWithZeros): for
// Ros1Chunk::stored.
// `first_connection`: the id of the first topic's connection (0 as rosbag numbers them: zeros after the records
// then parse as empty messages of that topic).
std::string Ros1ChunkRecords(const std::vector<TestMessage>& messages, uint64_t padding = 0,
                             uint32_t first_connection = 1);
// The same, written to `path`.
void WriteRos1BagChunks(const std::string& path, const std::vector<Ros1Chunk>& chunks);

// `data` compressed with "bz2", "lz4" (LZ4's frame format) or "zstd".
std::string CompressBytes(const std::string& compression, const std::string& data);
// `prefix` followed by `zeros` zero bytes, compressed with "bz2", "lz4" or "zstd" without ever holding the zeros:
// a bomb of gigabytes in kilobytes.
std::string CompressedWithZeros(const std::string& compression, const std::string& prefix, uint64_t zeros);

// An MCAP file of one chunk ("zstd" or "lz4") holding the records WriteMcap writes for `messages`, then a
// message on their first topic of `zeros` zero bytes (never held); its announced size `announced_size` when
// not 0.
void WriteMcapBomb(const std::string& path, const std::vector<TestMessage>& messages, const std::string& compression,
                   uint64_t zeros, uint64_t announced_size = 0);

}  // namespace vmap::testing
