#pragma once
// Logging goes through spdlog to stderr. The level is set once by the CLI (--verbose, --quiet).

#include <spdlog/spdlog.h>

namespace vmap {

// "quiet": warnings and errors only; "info": default; "debug": the why of every decision.
void ConfigureLogging(const std::string& level);

}  // namespace vmap
