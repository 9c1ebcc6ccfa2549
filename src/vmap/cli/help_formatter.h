// CLI11's help, less the default value it writes into a switch's name.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace vmap::cli {

// CLI11 names a switch that sets a value other than true by that value: "--no-odometry{false}". A user reads the
// flag, not the value it stores, so the help names it "--no-odometry", as it is typed.
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_option_name(const CLI::Option* option, bool is_positional) const override;
};

}  // namespace vmap::cli
