#pragma once
// SHA-1, only to compute git blob ids of downloaded weights (integrity against known copies, not security).

#include <cstdint>
#include <string>

namespace vmap::neural {

class Sha1 {
 public:
  Sha1();
  void Update(const void* data, size_t size);
  std::string HexDigest();  // finishes the hash; call once

 private:
  void Block(const uint8_t* block);
  uint32_t state_[5];
  uint8_t buffer_[64];
  size_t buffered_ = 0;
  uint64_t total_bytes_ = 0;
};

std::string Sha1Hex(const std::string& bytes);
// sha1("blob <size>\0" + contents), as `git hash-object FILE` prints. Throws InputError if unreadable.
std::string GitBlobId(const std::string& path);

}  // namespace vmap::neural
