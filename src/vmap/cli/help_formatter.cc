#include "vmap/cli/help_formatter.h"

namespace vmap::cli {

std::string HelpFormatter::make_option_name(const CLI::Option* option, bool is_positional) const {
  std::string name = CLI::Formatter::make_option_name(option, is_positional);
  // Flag names hold no braces (CLI11 refuses them), so every "{...}" is a stored value.
  for (size_t open = name.find('{'); open != std::string::npos; open = name.find('{', open)) {
    const size_t close = name.find('}', open);
    if (close == std::string::npos) break;
    name.erase(open, close - open + 1);
  }
  return name;
}

}  // namespace vmap::cli
