#include "vmap/core/natural_less.h"

#include <cctype>

namespace vmap {

bool NaturalLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      size_t i_end = i, j_end = j;
      while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
      while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
      // The decimals of a number (what comes before is the same in both names): "1700000000.05" before
      // "1700000000.5", as frames named by their times in seconds are. Digit by digit; of two that agree as far as the
      // shorter goes, the shorter first (its value is not larger).
      if (i >= 2 && a[i - 1] == '.' && std::isdigit(static_cast<unsigned char>(a[i - 2]))) {
        const int cmp = a.compare(i, std::min(i_end - i, j_end - j), b, j, std::min(i_end - i, j_end - j));
        if (cmp != 0) return cmp < 0;
        if (i_end - i != j_end - j) return i_end - i < j_end - j;
        i = i_end;
        j = j_end;
        continue;
      }
      // Compare digit runs as numbers without overflow: skip leading zeros, then length, then digits.
      size_t i_nz = i, j_nz = j;
      while (i_nz + 1 < i_end && a[i_nz] == '0') ++i_nz;
      while (j_nz + 1 < j_end && b[j_nz] == '0') ++j_nz;
      if (i_end - i_nz != j_end - j_nz) return i_end - i_nz < j_end - j_nz;
      const int cmp = a.compare(i_nz, i_end - i_nz, b, j_nz, j_end - j_nz);
      if (cmp != 0) return cmp < 0;
      if (i_end - i != j_end - j) return i_end - i < j_end - j;  // "01" after "1"
      i = i_end;
      j = j_end;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

}  // namespace vmap
