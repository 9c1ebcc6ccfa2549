#include "vmap/simulation/teach_run.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace vmap {

Camera RigCamera(const CameraRigOptions& camera) {
  const cv::Matx33d K = CameraMatrix(camera);
  Camera rig = Camera::Make(K(0, 0), K(1, 1), K(0, 2), K(1, 2), {}, cv::Size(camera.width, camera.height));
  rig.origin = "simulated camera";
  return rig;
}

Frame RenderFrame(const CorridorWorld& world, const CameraRigOptions& camera, const Pose2d& pose, int index,
                  double timestamp) {
  Frame frame;
  frame.index = frame.source_index = index;
  frame.timestamp = timestamp;
  frame.source_name = cv::format("frame_%06d", index);
  frame.color = RenderPolygons(world.polygons(), CameraView(camera, pose));
  cv::cvtColor(frame.color, frame.gray, cv::COLOR_BGR2GRAY);
  return frame;
}

RenderedFrameSource::RenderedFrameSource(const CorridorWorld& world, const CameraRigOptions& camera,
                                         std::vector<Pose2d> poses, double seconds_per_frame, std::string name)
    : world_(world), camera_(camera), poses_(std::move(poses)), seconds_per_frame_(seconds_per_frame) {
  info_.path = std::move(name);
  info_.format = SourceFormat::kImageFolder;
  info_.expected_frames = static_cast<long>(poses_.size());
  info_.native_size = info_.frame_size = cv::Size(camera.width, camera.height);
  info_.fps = 1.0 / seconds_per_frame;
  info_.camera = RigCamera(camera);
}

std::optional<Frame> RenderedFrameSource::Next() {
  if (next_ >= static_cast<int>(poses_.size())) return std::nullopt;
  Frame frame = RenderFrame(world_, camera_, poses_[next_], next_, next_ * seconds_per_frame_);
  ++next_;
  return frame;
}

TeachRun PlanTeachRun(const SimulatedRoute& route, const SimulationOptions& options) {
  TeachRun teach;
  teach.seconds_per_frame = 1.0 / options.rate;
  const double step = options.teach_speed * teach.seconds_per_frame;
  const double length = route.path.length();
  const int steps = static_cast<int>(std::ceil(length / step - 1e-9));
  for (int k = 0; k <= steps; ++k) {
    const double s = std::min(k * step, length);  // the last frame exactly at the goal
    const Pose2d pose = route.path.At(s);
    teach.poses.push_back(pose);
    teach.odometry.push_back({k * teach.seconds_per_frame, pose.x, pose.y, pose.yaw});
  }
  return teach;
}

}  // namespace vmap
