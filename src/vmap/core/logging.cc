#include "vmap/core/logging.h"

#include <memory>
#include <string_view>

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include "vmap/core/error.h"
#include "vmap/core/terminal_text.h"

namespace vmap {
namespace {

// The message as TerminalSafe text: a file name in a warning cannot drive the terminal or forge a line.
class TerminalSafeMessage : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& message, const std::tm&, spdlog::memory_buf_t& out) override {
    const std::string safe = TerminalSafe(std::string_view(message.payload.data(), message.payload.size()));
    out.append(safe.data(), safe.data() + safe.size());
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<TerminalSafeMessage>(); }
};

}  // namespace

void ConfigureLogging(const std::string& level) {
  auto logger = spdlog::get("vmap");
  if (!logger) logger = spdlog::stderr_color_mt("vmap");
  spdlog::set_default_logger(logger);
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  formatter->add_flag<TerminalSafeMessage>('*').set_pattern("[%^%l%$] %*");
  spdlog::set_formatter(std::move(formatter));
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
