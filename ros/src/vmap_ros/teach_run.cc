#include "vmap_ros/teach_run.h"

#include <chrono>

#include <spdlog/spdlog.h>

#include "vmap/core/error.h"

namespace vmap::ros_node {

TeachRun::TeachRun(const BuildPipelineOptions& options, size_t capacity)
    : source_(std::make_unique<TopicFrameSource>(options.input, options.source, capacity)) {
  result_ = std::async(std::launch::async, [this, options] {
    try {
      return RunBuildPipeline(options, source_.get());
    } catch (const std::exception& error) {
      // Said when it happens, not first at ~teach/stop: the camera's frames are no longer taken from here on.
      if (source_->pulled()) {
        spdlog::error("the teach run failed and takes no more frames: {}; call ~teach/stop", error.what());
      }
      throw;
    }
  });
  // The pipeline asks for its first frame once it is set up; an error before that is the start's.
  while (!source_->pulled()) {
    if (result_.wait_for(std::chrono::milliseconds(20)) == std::future_status::ready) {
      stopped_ = true;
      result_.get();  // throws the pipeline's error
      throw InputError("the teach run ended before its first frame");
    }
  }
}

TeachRun::~TeachRun() {
  if (stopped_) return;
  try {
    Stop();
  } catch (const std::exception& error) {
    spdlog::error("the teach run failed: {}", error.what());
  }
}

BuildPipelineResult TeachRun::Stop() {
  source_->End();
  stopped_ = true;
  return result_.get();
}

}  // namespace vmap::ros_node
