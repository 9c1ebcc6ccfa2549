#include "vmap/localization/lost_frame_matcher.h"

#include <utility>

#include "vmap/map/map_io.h"

namespace vmap {

LostFrameMatcher::LostFrameMatcher(std::unique_ptr<Matcher> matcher, const VisualMap& map,
                                   std::filesystem::path directory)
    : matcher_(std::move(matcher)), map_(map), directory_(std::move(directory)), key_features_(map.key_images.size()) {}

const ImageFeatures& LostFrameMatcher::KeyFeatures(int key) {
  std::shared_ptr<const ImageFeatures>& features = key_features_.at(key);
  if (!features)
    features = matcher_->ExtractFrame(ReadKeyImage(directory_, map_.key_images[key], /*grayscale=*/true), cv::Mat());
  return *features;
}

}  // namespace vmap
