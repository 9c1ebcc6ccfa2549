#pragma once
// A lost frame's second look (LocalizerOptions::lost_frame_features): the map's ORB with more features, and the key
// images' features it extracts, each read again from the map's directory when first needed. Across seasons 500
// features match too few of a right key image's for chance; a lost frame is compared again so
// (Localizer::CompareLostFrameAgain, localizer_relocalize.cc).

#include <filesystem>
#include <memory>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/map/visual_map.h"

namespace vmap {

class LostFrameMatcher {
 public:
  // `matcher`: the map's matcher with more features; `map` (which must outlive this) holds the key images read from
  // `directory`.
  LostFrameMatcher(std::unique_ptr<Matcher> matcher, const VisualMap& map, std::filesystem::path directory);

  const Matcher& matcher() const { return *matcher_; }
  // Key image `key`'s features as matcher() extracts them. Throws InputError where its file is not at hand (a map whose
  // features came from the cache alone).
  const ImageFeatures& KeyFeatures(int key);

 private:
  std::unique_ptr<Matcher> matcher_;
  const VisualMap& map_;
  std::filesystem::path directory_;
  std::vector<std::shared_ptr<const ImageFeatures>> key_features_;  // per key image; null: not yet extracted
};

}  // namespace vmap
