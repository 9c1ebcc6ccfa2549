#include "vmap/core/logging.h"

#include <spdlog/sinks/stdout_color_sinks.h>

#include "vmap/core/error.h"

namespace vmap {

void ConfigureLogging(const std::string& level) {
  auto logger = spdlog::get("vmap");
  if (!logger) logger = spdlog::stderr_color_mt("vmap");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%^%l%$] %v");
  if (level == "quiet")
    spdlog::set_level(spdlog::level::warn);
  else if (level == "info")
    spdlog::set_level(spdlog::level::info);
  else if (level == "debug")
    spdlog::set_level(spdlog::level::debug);
  else
    throw InputError("unknown log level '" + level + "'; use quiet, info or debug");
}

}  // namespace vmap
