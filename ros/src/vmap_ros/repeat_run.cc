#include "vmap_ros/repeat_run.h"

#include <algorithm>
#include <future>

#include <ros/console.h>

#include "vmap/control/taught_route.h"
#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/sources/image_frame.h"

namespace vmap::ros_node {

RepeatRun::RepeatRun(const LocalizePipelineOptions& options, const ControllerOptions& controller)
    : session_(options),
      route_(session_.localizer().route()),
      controller_(MakeTaughtRoute(session_.map(), route_, session_.teach_odometry()), controller) {
  key_images_.resize(session_.map().key_images.size());
}

RepeatStep RepeatRun::Step(const CameraImage& image, double time, double wall_time, const OdometrySample* odometry) {
  RepeatStep step;
  step.localization = Localize(image, odometry);
  bool by_wall_clock = false;
  const double controller_time = clock_.Tick(time, wall_time, &by_wall_clock);
  if (by_wall_clock) {
    ROS_WARN_THROTTLE(10.0,
                      "the camera's clock did not advance (stamped %.3f s; a bag played in a loop? a clock reset? "
                      "/use_sim_time without /clock?): the controller keeps time by the wall clock meanwhile",
                      time);
  }
  step.control = controller_.Update(controller_time, step.localization, odometry);
  return step;
}

LocalizationResult RepeatRun::Localize(const CameraImage& image, const OdometrySample* odometry) {
  const cv::Mat& pixels = image.color.empty() ? image.gray : image.color;
  frame_ = FrameFromImage(pixels, frames_, session_.map().input.frame_size, "the camera image");
  frame_.timestamp = image.stamp;
  if (odometry) frame_.odometry = *odometry;
  Localizer& localizer = session_.localizer();
  const auto features = session_.matcher().ExtractFrame(frame_.gray, frame_.color);
  // While tracking, the frame is compared with key and next_key: the two comparisons run side by side (the
  // localizer takes comparisons made ahead instead of making them again, with the same result), which shortens
  // the time from image to command.
  std::vector<KeyComparison> ahead;
  const std::vector<int> likely = localizer.LikelyKeys();
  if (likely.size() == 2) {
    std::future<KeyComparison> second =
        std::async(std::launch::async, [&] { return localizer.Compare(*features, likely[1]); });
    ahead.push_back(localizer.Compare(*features, likely[0]));
    ahead.push_back(second.get());
  }
  LocalizationResult result = localizer.Localize(frame_, *features, std::move(ahead));
  ++frames_;
  return result;
}

cv::Mat RepeatRun::KeyImage(int key) {
  if (key < 0 || key >= static_cast<int>(key_images_.size())) return {};
  cv::Mat& image = key_images_[key];
  if (image.empty()) {
    // Read as every reader of a map reads a key image (checked again: the map may have changed on disk since); a
    // key image that cannot be read leaves the debug figure without it, the run goes on.
    try {
      image = ReadKeyImage(directory(), map().key_images[key], /*grayscale=*/false, map().input.frame_size);
    } catch (const InputError& error) {
      ROS_WARN_THROTTLE(10.0, "%s", error.what());
    }
  }
  return image;
}

}  // namespace vmap::ros_node
