#include "vmap/simulation/teach_run.h"

#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/recorded_options.h"

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
  const auto start = std::chrono::steady_clock::now();
  Frame frame = RenderFrame(world_, camera_, poses_[next_], next_, next_ * seconds_per_frame_);
  render_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++next_;
  return frame;
}

TeachRun RunTeach(const SimulatedRoute& route, const CorridorWorld& world, const SimulationOptions& options,
                  const Matcher& matcher, double tau, const std::filesystem::path& map_directory) {
  const auto start = std::chrono::steady_clock::now();
  TeachRun teach;
  const double dt = 1.0 / options.rate;
  const double step = options.teach_speed * dt;
  const double length = route.path.length();
  const int steps = static_cast<int>(std::ceil(length / step - 1e-9));
  for (int k = 0; k <= steps; ++k) {
    const double s = std::min(k * step, length);  // the last frame exactly at the goal
    const Pose2d pose = route.path.At(s);
    teach.poses.push_back(pose);
    teach.odometry.push_back({k * dt, pose.x, pose.y, pose.yaw});
  }
  RenderedFrameSource source(world, options.camera, teach.poses, dt, "simulated teach run (" + route.name + ")");
  MapBuilderOptions builder;
  builder.key_images.tau = tau;
  builder.show_progress = false;
  RecordedOptions record;
  record.matcher_json = matcher.DescribeOptionsJson();
  record.builder = builder;
  teach.map = BuildMap(source, matcher, builder, map_directory, ToJson(record).dump());
  teach.render_seconds = source.render_seconds();
  teach.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return teach;
}

}  // namespace vmap
