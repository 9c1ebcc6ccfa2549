#pragma once
// A file read at explicit offsets, with every read checked against the file's size: what the recording
// readers use so that a length field in a damaged file can never make them read (or allocate) past its end.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace vmap {

class BinaryFile {
 public:
  explicit BinaryFile(const std::string& path);  // throws InputError when it cannot be opened
  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }
  // Reads `count` bytes at `offset` into `out` (resized). Throws InputError naming the file, the offset and
  // `what` when the file ends first.
  void Read(uint64_t offset, uint64_t count, std::vector<uint8_t>* out, const char* what);
  void Read(uint64_t offset, uint64_t count, uint8_t* out, const char* what);
  [[noreturn]] void Damaged(uint64_t offset, const std::string& problem) const;

 private:
  struct Closer {
    void operator()(std::FILE* file) const { std::fclose(file); }
  };
  std::string path_;
  std::unique_ptr<std::FILE, Closer> file_;
  uint64_t size_ = 0;
};

// Little-endian integers from a byte pointer (the callers check the bounds).
inline uint16_t LoadU16(const uint8_t* b) { return static_cast<uint16_t>(b[0] | b[1] << 8); }
inline uint32_t LoadU32(const uint8_t* b) {
  return uint32_t{b[0]} | uint32_t{b[1]} << 8 | uint32_t{b[2]} << 16 | uint32_t{b[3]} << 24;
}
inline uint64_t LoadU64(const uint8_t* b) { return uint64_t{LoadU32(b)} | uint64_t{LoadU32(b + 4)} << 32; }

}  // namespace vmap
