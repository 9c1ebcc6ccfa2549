#pragma once
// A file read at explicit offsets, with every read checked against the file's size: what the recording
// readers use so that a length field in a damaged file can never make them read (or allocate) past its end.
// Opened through core/contained_file.h: never a FIFO (which would block), a device or a folder, and for a
// member of a recording's folder never a symbolic link that leads out of it.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "vmap/core/contained_file.h"

namespace vmap {

class BinaryFile {
 public:
  // A recording the user named. Throws InputError when it is not a regular file that can be opened.
  explicit BinaryFile(const std::string& path);
  // `name` inside the recording's folder `folder` (an .mcap file of a rosbag2 folder). Throws InputError also
  // when it resolves outside the folder.
  BinaryFile(const std::filesystem::path& folder, const std::string& name);

  const std::string& path() const { return path_; }
  uint64_t size() const { return file_.size(); }
  // Reads `count` bytes at `offset` into `out` (resized). Throws InputError naming the file, the offset and
  // `what` when the file ends first.
  void Read(uint64_t offset, uint64_t count, std::vector<uint8_t>* out, const char* what);
  void Read(uint64_t offset, uint64_t count, uint8_t* out, const char* what);
  [[noreturn]] void Damaged(uint64_t offset, const std::string& problem) const;
  // The same for a size past RecordingLimits: throws RecordingLimitExceeded.
  [[noreturn]] void OverLimit(uint64_t offset, const std::string& problem) const;

 private:
  static ContainedFile Opened(std::optional<ContainedFile> (*open)(const std::filesystem::path&, std::string*),
                              const std::string& path);
  static ContainedFile OpenedInside(const std::filesystem::path& folder, const std::string& name);

  std::string path_;
  ContainedFile file_;
};

// Little-endian integers from a byte pointer (the callers check the bounds).
inline uint16_t LoadU16(const uint8_t* b) { return static_cast<uint16_t>(b[0] | b[1] << 8); }
inline uint32_t LoadU32(const uint8_t* b) {
  return uint32_t{b[0]} | uint32_t{b[1]} << 8 | uint32_t{b[2]} << 16 | uint32_t{b[3]} << 24;
}
inline uint64_t LoadU64(const uint8_t* b) { return uint64_t{LoadU32(b)} | uint64_t{LoadU32(b + 4)} << 32; }

}  // namespace vmap
