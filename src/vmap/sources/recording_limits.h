#pragma once
// What reading a recording may cost, whatever its bytes announce: a recording is untrusted input (a file
// someone sent), and its containers announce sizes that are allocated or produced before they can be checked
// (a chunk's decompressed size, a message's zstd frame, a database compressed whole). Each limit is what a
// frame vmap reads can need, so that a real recording never reaches one and a crafted one is refused after
// little work, with an error naming the file and the offset.

#include <cstdint>
#include <string>

#include "vmap/core/error.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// A recording that asks for more than RecordingLimits allow: crafted or damaged beyond use. Unlike other damage
// (a recording cut short, whose frames before the cut are still read), it ends the reading with an error.
class RecordingLimitExceeded : public InputError {
 public:
  using InputError::InputError;
};

struct RecordingLimits {
  // The largest message once decompressed: a frame of the 64-megapixel cap at 4 bytes a pixel (rgba8, the
  // widest encoding vmap reads), and 1 MiB for its header.
  uint64_t max_message_bytes = uint64_t{kMaxFramePixels} * 4 + (uint64_t{1} << 20);
  // The largest chunk once decompressed: recorders close a chunk once it passes its threshold (768 KiB by
  // default in rosbag and MCAP writers), so a chunk holds at most one message past some MB of smaller ones.
  uint64_t max_chunk_bytes = max_message_bytes + (uint64_t{64} << 20);
  // Decompressed bytes in one pass through the recording (counting topics, reading frames): `pass_bytes_floor`
  // plus `pass_bytes_per_stored_byte` times the stored (compressed) size. Camera images compress 1.5:1 to 5:1
  // with lz4, zstd or bz2; 64:1 is met only by frames of one colour, while a chunk of zeros reaches 1000:1
  // and more (a 176 KB bag of 100 chunks of 256 MiB of zeros took 56 s to count). Also the cap on the
  // decompressed copy of a rosbag2 database compressed whole (--compression-mode file) in TMPDIR.
  uint64_t pass_bytes_floor = uint64_t{256} << 20;
  uint64_t pass_bytes_per_stored_byte = 64;
  // Records (messages, connections, ...) parsed in one pass: `pass_records_floor` plus one per
  // `stored_bytes_per_record` stored bytes. A message is stored in some bytes at least, even compressed (an IMU's
  // 300-byte messages take 30 to 100); 8 zero bytes parse as an empty ROS 1 record, so a chunk of zeros would
  // otherwise be tens of millions of them.
  uint64_t pass_records_floor = uint64_t{1} << 20;
  uint64_t stored_bytes_per_record = 4;

  // The limits for frames of at most `max_frame_pixels` (FrameSourceOptions::max_frame_pixels).
  static RecordingLimits ForFrames(long max_frame_pixels);
  // The decompressed bytes one pass may produce from a recording of `stored_bytes`.
  uint64_t PassBytes(uint64_t stored_bytes) const;
  // The records one pass may parse in a recording of `stored_bytes`.
  uint64_t PassRecords(uint64_t stored_bytes) const;
};

// What one pass through a recording costs, counted against RecordingLimits: bytes decompressed and records
// parsed. The readers count before they work, and throw RecordingLimitExceeded with the refusal.
class PassBudget {
 public:
  PassBudget() = default;
  PassBudget(const RecordingLimits& limits, uint64_t stored_bytes);
  // Starts a new pass.
  void Reset() { bytes_ = records_ = 0; }
  // What may still be decompressed in this pass.
  uint64_t bytes_left() const { return max_bytes_ - bytes_; }
  // Counts `bytes` about to be decompressed; "" when they fit in the pass's budget, else why not (for the
  // caller to throw naming the file and offset), counting nothing.
  std::string Spend(uint64_t bytes);
  // Spend's refusal: what the budget is, and why it was exceeded.
  std::string WhyBytesExceeded() const;
  // Counts one record parsed; "" while the pass may parse it, else why not.
  std::string CountRecord() { return ++records_ <= max_records_ ? std::string() : WhyRecordsExceeded(); }

 private:
  std::string WhyRecordsExceeded() const;

  RecordingLimits limits_;
  uint64_t stored_bytes_ = 0;
  uint64_t max_bytes_ = UINT64_MAX, max_records_ = UINT64_MAX;
  uint64_t bytes_ = 0, records_ = 0;
};

}  // namespace vmap
