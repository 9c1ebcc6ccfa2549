#pragma once
// Python keyword arguments read as the flags of a vmap command: the keyword `max_iters` is the flag
// --max-iters, bound by the same Add*Options calls the command uses (cli/common_options.h), so the module
// accepts exactly the command's options, with its defaults, parsing and checks, and no list of its own.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vmap/cli/option_flags.h"

namespace vmap::python {

class KeywordOptions {
 public:
  // `function`: the Python function's name, for messages ("vmap.build_map").
  explicit KeywordOptions(std::string function);

  // Where the caller binds the command's flags (AddSourceOptions(command(), ..., option_flags()), ...).
  CLI::App* command() { return &command_; }
  cli::OptionFlags& option_flags() { return option_flags_; }

  // Sets the bound fields from `kwargs` (None keeps a default; True/False switch a flag on/off). An unknown
  // keyword is a TypeError listing the valid ones; a value the flag refuses is a vmap.Error naming the keyword.
  void Parse(const pybind11::kwargs& kwargs);

  // The keywords accepted, sorted.
  std::vector<std::string> Keywords() const;

  // Runs `work`; an OptionError or InputError from it comes out in the keywords' words ("first must be ...").
  void Run(const std::function<void()>& work) const;

  // `text` with every flag of the command ("--max-iters") written as its keyword ("max_iters").
  std::string InKeywords(std::string text) const;

 private:
  std::string function_;
  CLI::App command_;
  cli::OptionFlags option_flags_;
};

}  // namespace vmap::python
