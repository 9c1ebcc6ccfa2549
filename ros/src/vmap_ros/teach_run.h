#pragma once
// A teach run as the node drives it: `vmap build`'s pipeline (pipelines/build_pipeline.h) on a thread of its own,
// pulling the camera's frames from a TopicFrameSource; stopping ends the input, and the map is finished and
// committed atomically, as `vmap build --until-interrupted` finishes a camera's map.

#include <future>
#include <memory>
#include <optional>
#include <thread>

#include "vmap/pipelines/build_pipeline.h"

#include "vmap_ros/topic_frame_source.h"

namespace vmap::ros_node {

class TeachRun {
 public:
  // Starts the pipeline on `options` (input: the image topic, recorded; output: the map directory) and returns
  // once it waits for the first frame: the options checked, the output folder claimed (one that is not a vmap map is
  // refused, and left as it was), the matcher created. Throws what the pipeline threw before that (InputError).
  // `capacity`: frames held while the builder is busy (TopicFrameSource).
  TeachRun(const BuildPipelineOptions& options, size_t capacity);
  // A run not stopped is stopped: its map is finished and committed.
  ~TeachRun();
  TeachRun(const TeachRun&) = delete;
  TeachRun& operator=(const TeachRun&) = delete;

  TopicFrameSource& source() { return *source_; }
  // Ends the input and waits for the map. Throws the pipeline's error (InputError) when it failed.
  BuildPipelineResult Stop();
  bool stopped() const { return stopped_; }

 private:
  std::unique_ptr<TopicFrameSource> source_;
  std::future<BuildPipelineResult> result_;
  bool stopped_ = false;
};

}  // namespace vmap::ros_node
