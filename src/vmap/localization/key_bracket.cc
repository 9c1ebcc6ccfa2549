#include "vmap/localization/key_bracket.h"

namespace vmap {

std::pair<int, int> KeysAround(const VisualMap& map, int source_index) {
  int before = -1, after = -1;
  for (int k = 0; k < static_cast<int>(map.key_images.size()); ++k) {
    const int s = map.key_images[k].source_index;
    if (s <= source_index && (before < 0 || s >= map.key_images[before].source_index)) before = k;
    if (s >= source_index && (after < 0 || s < map.key_images[after].source_index)) after = k;
  }
  return {before, after};
}

}  // namespace vmap
