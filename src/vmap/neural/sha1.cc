#include "vmap/neural/sha1.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"

namespace vmap::neural {

namespace {
uint32_t Rotl(uint32_t x, int n) { return (x << n) | (x >> (32 - n)); }
}  // namespace

Sha1::Sha1() : state_{0x67452301u, 0xEFCDAB89u, 0x98BADCFEu, 0x10325476u, 0xC3D2E1F0u} {}

void Sha1::Block(const uint8_t* block) {
  uint32_t w[80];
  for (int i = 0; i < 16; ++i) {
    w[i] = (uint32_t(block[4 * i]) << 24) | (uint32_t(block[4 * i + 1]) << 16) | (uint32_t(block[4 * i + 2]) << 8) |
           uint32_t(block[4 * i + 3]);
  }
  for (int i = 16; i < 80; ++i) w[i] = Rotl(w[i - 3] ^ w[i - 8] ^ w[i - 14] ^ w[i - 16], 1);
  uint32_t a = state_[0], b = state_[1], c = state_[2], d = state_[3], e = state_[4];
  for (int i = 0; i < 80; ++i) {
    uint32_t f, k;
    if (i < 20)
      f = (b & c) | (~b & d), k = 0x5A827999u;
    else if (i < 40)
      f = b ^ c ^ d, k = 0x6ED9EBA1u;
    else if (i < 60)
      f = (b & c) | (b & d) | (c & d), k = 0x8F1BBCDCu;
    else
      f = b ^ c ^ d, k = 0xCA62C1D6u;
    const uint32_t t = Rotl(a, 5) + f + e + k + w[i];
    e = d, d = c, c = Rotl(b, 30), b = a, a = t;
  }
  state_[0] += a, state_[1] += b, state_[2] += c, state_[3] += d, state_[4] += e;
}

void Sha1::Update(const void* data, size_t size) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  total_bytes_ += size;
  while (size > 0) {
    const size_t take = std::min(size, sizeof(buffer_) - buffered_);
    std::memcpy(buffer_ + buffered_, bytes, take);
    buffered_ += take, bytes += take, size -= take;
    if (buffered_ == sizeof(buffer_)) Block(buffer_), buffered_ = 0;
  }
}

std::string Sha1::HexDigest() {
  const uint64_t bit_length = total_bytes_ * 8;
  const uint8_t pad_start = 0x80, zero = 0;
  Update(&pad_start, 1);
  while (buffered_ != 56) Update(&zero, 1);
  uint8_t length_be[8];
  for (int i = 0; i < 8; ++i) length_be[i] = uint8_t(bit_length >> (56 - 8 * i));
  Update(length_be, 8);
  char hex[41];
  for (int i = 0; i < 5; ++i) std::snprintf(hex + 8 * i, 9, "%08x", state_[i]);
  return std::string(hex, 40);
}

std::string Sha1Hex(const std::string& bytes) {
  Sha1 sha;
  sha.Update(bytes.data(), bytes.size());
  return sha.HexDigest();
}

std::string GitBlobId(const std::string& path) {
  // Opened without blocking and refused unless a regular file: a FIFO or a device is never read.
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
  if (!file) throw InputError("cannot verify '" + path + "': it " + why_not + "; give a weights file");
  constexpr std::uint64_t kMaxBytes = 1ull << 30;  // the largest published weights are some 50 MB
  if (file->size() > kMaxBytes) {
    throw InputError("cannot verify '" + path + "': it is larger than 1 GB, more than any weights file");
  }
  Sha1 sha;
  const std::string header = "blob " + std::to_string(file->size());
  sha.Update(header.data(), header.size() + 1);  // the terminating NUL is part of git's header
  std::vector<char> chunk(1 << 20);
  for (std::uint64_t at = 0; at < file->size(); at += chunk.size()) {
    const size_t bytes = static_cast<size_t>(std::min<std::uint64_t>(chunk.size(), file->size() - at));
    if (!file->Read(at, chunk.data(), bytes)) throw InputError("cannot read '" + path + "' to verify it");
    sha.Update(chunk.data(), bytes);
  }
  return sha.HexDigest();
}

}  // namespace vmap::neural
