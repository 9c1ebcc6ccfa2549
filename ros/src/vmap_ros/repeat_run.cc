#include "vmap_ros/repeat_run.h"

#include <opencv2/imgcodecs.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/localization/route.h"
#include "vmap/map/map_io.h"
#include "vmap/sources/image_frame.h"

namespace vmap::ros_node {

RepeatRun::RepeatRun(const RepeatRequest& request) {
  request.localizer.Check();
  // The header first: a missing or malformed map, or a goal it has not, is refused before its key images load.
  const VisualMap header = ReadMap(request.map);
  const int last = static_cast<int>(header.key_images.size()) - 1;
  const int goal = request.goal >= 0 ? request.goal : last;
  const int start = request.start >= 0 ? request.start : 0;
  for (const auto& [name, key] : {std::pair<const char*, int>{"goal", goal}, {"start", start}}) {
    if (key > last) {
      throw InputError("the map '" + request.map.string() + "' has key images 0 to " + std::to_string(last) +
                       ", no key image " + std::to_string(key) + "; give another " + name);
    }
  }
  KeyImageStoreOptions store;
  store.use_cache = request.cache;
  store.thumbnail_width = request.localizer.ranking.thumbnail_width;
  opened_ = std::make_unique<LocalizationMap>(OpenLocalizationMap(request.map, store));
  LocalizerOptions options = request.localizer;
  options.route = PlanRoute(opened_->map, start, goal).keys;
  options_ = FollowMap(*opened_, options, QueryResize(opened_->map, ""));
  options_.Check();
  localizer_ = std::make_unique<Localizer>(opened_->map, opened_->keys, *opened_->matcher, options_);
  key_images_.resize(opened_->map.key_images.size());
}

RepeatRun::~RepeatRun() = default;

LocalizationResult RepeatRun::Localize(const CameraImage& image) {
  const cv::Mat& pixels = image.color.empty() ? image.gray : image.color;
  frame_ = FrameFromImage(pixels, frames_, opened_->map.input.frame_size, "the camera image");
  frame_.timestamp = image.stamp;
  const auto features = opened_->matcher->ExtractFrame(frame_.gray, frame_.color);
  LocalizationResult result = localizer_->Localize(frame_, *features);
  ++frames_;
  return result;
}

void RepeatRun::Reset() { localizer_->Reset(); }

cv::Mat RepeatRun::KeyImage(int key) {
  if (key < 0 || key >= static_cast<int>(key_images_.size())) return {};
  cv::Mat& image = key_images_[key];
  if (image.empty()) {
    std::string why_not, bytes;
    const std::optional<ContainedFile> file =
        ContainedFile::Open(opened_->directory, opened_->map.key_images[key].image_file, &why_not);
    if (file && file->ReadAll(&bytes)) {
      image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, bytes.data()), cv::IMREAD_COLOR);
    }
  }
  return image;
}

}  // namespace vmap::ros_node
