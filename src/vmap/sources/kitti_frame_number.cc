#include "vmap/sources/kitti_frame_number.h"

#include <filesystem>

namespace vmap {

std::optional<int> KittiFrameNumber(const std::string& file_name) {
  const std::string stem = std::filesystem::path(file_name).stem().string();
  constexpr size_t kMaxDigits = 9;  // below INT_MAX whatever the digits
  if (stem.empty() || stem.size() > kMaxDigits) return std::nullopt;
  int number = 0;
  for (const char c : stem) {
    if (c < '0' || c > '9') return std::nullopt;
    number = number * 10 + (c - '0');
  }
  return number;
}

}  // namespace vmap
