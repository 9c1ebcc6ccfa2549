#pragma once
// FNV-1a, 64 bits: what vmap uses to notice that something changed (a cache's inputs, a camera mask's pixels), not to
// resist an adversary.

#include <cstdint>
#include <string_view>

namespace vmap {

inline constexpr std::uint64_t kFnv1aOffsetBasis = 0xcbf29ce484222325ull;

// The hash of `bytes` continued from `hash` (the offset basis for a new one): hashing a text in pieces, each from the
// hash of the pieces before, gives the hash of the whole.
inline std::uint64_t Fnv1a(std::string_view bytes, std::uint64_t hash = kFnv1aOffsetBasis) {
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 0x100000001b3ull;
  }
  return hash;
}

}  // namespace vmap
