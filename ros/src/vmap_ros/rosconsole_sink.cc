#include "vmap_ros/rosconsole_sink.h"

#include <memory>
#include <mutex>
#include <string>

#include <ros/console.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

namespace vmap::ros_node {
namespace {

class RosconsoleSink final : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    const std::string text(message.payload.data(), message.payload.size());
    switch (message.level) {
      case spdlog::level::trace:
      case spdlog::level::debug:
        ROS_DEBUG("%s", text.c_str());
        break;
      case spdlog::level::info:
        ROS_INFO("%s", text.c_str());
        break;
      case spdlog::level::warn:
        ROS_WARN("%s", text.c_str());
        break;
      default:
        ROS_ERROR("%s", text.c_str());
        break;
    }
  }
  void flush_() override {}
};

}  // namespace

void LogThroughRosconsole() {
  auto logger = std::make_shared<spdlog::logger>("vmap", std::make_shared<RosconsoleSink>());
  logger->set_level(spdlog::level::info);
  spdlog::set_default_logger(logger);
}

}  // namespace vmap::ros_node
