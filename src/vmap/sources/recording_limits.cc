#include "vmap/sources/recording_limits.h"

#include <algorithm>

namespace vmap {

RecordingLimits RecordingLimits::ForFrames(long max_frame_pixels) {
  RecordingLimits limits;
  limits.max_message_bytes = static_cast<uint64_t>(std::max(max_frame_pixels, 1L)) * 4 + (uint64_t{1} << 20);
  limits.max_chunk_bytes = limits.max_message_bytes + (uint64_t{64} << 20);
  return limits;
}

namespace {

uint64_t SaturatingAdd(uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }

}  // namespace

uint64_t RecordingLimits::PassBytes(uint64_t stored_bytes) const {
  const uint64_t per_byte = std::max<uint64_t>(pass_bytes_per_stored_byte, 1);
  return SaturatingAdd(stored_bytes > UINT64_MAX / per_byte ? UINT64_MAX : stored_bytes * per_byte, pass_bytes_floor);
}

uint64_t RecordingLimits::PassRecords(uint64_t stored_bytes) const {
  return SaturatingAdd(stored_bytes / std::max<uint64_t>(stored_bytes_per_record, 1), pass_records_floor);
}

PassBudget::PassBudget(const RecordingLimits& limits, uint64_t stored_bytes)
    : limits_(limits),
      stored_bytes_(stored_bytes),
      max_bytes_(limits.PassBytes(stored_bytes)),
      max_records_(limits.PassRecords(stored_bytes)) {}

std::string PassBudget::Spend(uint64_t bytes) {
  if (bytes > bytes_left()) return WhyBytesExceeded();
  bytes_ += bytes;
  return "";
}

std::string PassBudget::WhyBytesExceeded() const {
  return "its data decompresses to more than " + std::to_string(max_bytes_ >> 20) + " MiB (" +
         std::to_string(limits_.pass_bytes_per_stored_byte) + " times its " + std::to_string(stored_bytes_) +
         " bytes, plus " + std::to_string(limits_.pass_bytes_floor >> 20) +
         " MiB), more than camera frames ever compress to: a decompression bomb, or damage";
}

std::string PassBudget::WhyRecordsExceeded() const {
  return "it holds more than " + std::to_string(max_records_) + " records (one per " +
         std::to_string(limits_.stored_bytes_per_record) + " of its " + std::to_string(stored_bytes_) +
         " bytes, plus " + std::to_string(limits_.pass_records_floor) +
         "), more than a recording of its size holds: a decompression bomb, or damage";
}

}  // namespace vmap
