#pragma once
// The teach run of a simulation: the route driven along its centre line at the teach speed, each frame rendered
// as the robot's camera sees it (a FrameSource like any input: the simulate pipeline builds the map from it with
// the build pipeline, as `vmap build` builds one).

#include <vector>

#include "vmap/simulation/corridor_world.h"
#include "vmap/simulation/route_path.h"
#include "vmap/simulation/simulation_options.h"
#include "vmap/sources/frame_source.h"
#include "vmap/sources/odometry.h"

namespace vmap {

// Frames rendered on demand, one per pose (nothing is held but the world): a FrameSource like any input, with
// the rig's pinhole camera as its intrinsics and timestamps `seconds_per_frame` apart.
class RenderedFrameSource : public FrameSource {
 public:
  RenderedFrameSource(const CorridorWorld& world, const CameraRigOptions& camera, std::vector<Pose2d> poses,
                      double seconds_per_frame, std::string name);
  std::optional<Frame> Next() override;
  const SequenceInfo& info() const override { return info_; }

 private:
  const CorridorWorld& world_;
  CameraRigOptions camera_;
  std::vector<Pose2d> poses_;
  double seconds_per_frame_;
  SequenceInfo info_;
  int next_ = 0;
};

// One rendered frame as a source delivers it (BGR and grey).
Frame RenderFrame(const CorridorWorld& world, const CameraRigOptions& camera, const Pose2d& pose, int index,
                  double timestamp);

// The rig's camera as vmap describes cameras (pinhole, no distortion).
Camera RigCamera(const CameraRigOptions& camera);

// Where the teach run takes each frame and its odometry.
struct TeachRun {
  std::vector<Pose2d> poses;             // of each frame, on the route's centre line
  std::vector<OdometrySample> odometry;  // the teach run's odometry (exact: the poses, timestamped)
  double seconds_per_frame = 0.0;
};

// `route` driven along its centre line at options.teach_speed, a frame every 1 / options.rate seconds, the last
// frame exactly at the goal.
TeachRun PlanTeachRun(const SimulatedRoute& route, const SimulationOptions& options);

}  // namespace vmap
